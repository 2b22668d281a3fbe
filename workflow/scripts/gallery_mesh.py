"""One of the suite's own gallery meshes, or a packaged real mesh, as OBJ (rule ``gallery_mesh``,
workflow/rules/gallery.smk; :func:`mcfbench.studies.gallery.write_generated_mesh`)."""

import logging

from mcfbench.studies.gallery.job import write_generated_mesh

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO, force=True)  # noqa: F821
write_generated_mesh(snakemake.params.entry, snakemake.output[0])  # noqa: F821
logging.info("%s -> %s", snakemake.params.entry, snakemake.output[0])  # noqa: F821
