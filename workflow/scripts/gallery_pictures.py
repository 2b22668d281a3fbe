"""The gallery's picture grid: per mesh the initial surface and every scheme's
last frame (rule ``gallery_pictures``, workflow/rules/gallery.smk)."""

import logging

from mcfbench.pipeline import code_digests
from mcfbench.storage.frames import load_frames
from mcfbench.storage.run_store import frames_path, read_run
from mcfbench.studies.gallery.plan import gallery_specs
from mcfbench.studies.gallery.plots import gallery_grid

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
plan = sm.params.plan
specs = gallery_specs(plan)
digests = code_digests(specs.values())
entries = {key: (read_run(spec, digests[spec]), load_frames(frames_path(spec)))
           for key, spec in specs.items()}
gallery_grid(entries, [sm.output.png, sm.output.pdf], list(plan["meshes"]), plan["schemes"])
logging.info("wrote %s", ", ".join(sm.output))
