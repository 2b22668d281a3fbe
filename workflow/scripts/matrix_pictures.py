"""The picture grid of the benchmark matrix: the final surfaces, scheme x problem, at
each problem's coarsest level, from the saved frames in the run store
(:func:`mcfbench.studies.matrix.plots.picture_grid`).

Called by rule ``matrix_pictures`` (workflow/rules/matrix.smk).
"""

import logging

from mcfbench.pipeline import code_digests
from mcfbench.storage.frames import load_frames
from mcfbench.storage.run_store import frames_path, read_run
from mcfbench.studies.matrix.plan import picture_specs
from mcfbench.studies.matrix.plots import picture_grid

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
plan = sm.params.plan
specs = picture_specs(plan)
digests = code_digests(specs.values())
entries = {key: (read_run(spec, digests[spec]), load_frames(frames_path(spec)))
           for key, spec in specs.items()}
picture_grid(entries, [sm.output.png, sm.output.pdf], list(plan["problems"]), plan["schemes"])
logging.info("wrote %s", ", ".join(sm.output))
