"""The gallery table, mesh x scheme (rule ``gallery_table``,
workflow/rules/gallery.smk; :func:`mcfbench.studies.gallery.tables.gallery_table`)."""

import logging

from mcfbench.pipeline import code_digests
from mcfbench.presentation.tables import csv
from mcfbench.storage.atomic import write_text
from mcfbench.storage.frames import load_frames
from mcfbench.storage.run_store import frames_path, read_runs
from mcfbench.studies.gallery.plan import gallery_specs
from mcfbench.studies.gallery.tables import gallery_markdown, gallery_table, initial_triangles
from mcfbench.studies.matrix.tables import FLOAT_FORMAT

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
specs = list(gallery_specs(sm.params.plan).values())
records = read_runs(code_digests(specs))
table = gallery_table([records[spec] for spec in specs],
                      [initial_triangles(load_frames(frames_path(spec))) for spec in specs])
write_text(sm.output.csv, csv(table, FLOAT_FORMAT))
write_text(sm.output.md, gallery_markdown(table, sm.params.plan))
logging.info("\n%s", table.to_string())
