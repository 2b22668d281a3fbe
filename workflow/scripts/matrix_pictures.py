"""The picture grid of the benchmark matrix: the final surfaces, scheme x problem, at
each problem's coarsest level, from the saved frames
(:func:`mcfbench.studies.matrix.plots.picture_grid`).

Called by rule ``matrix_pictures`` (workflow/rules/matrix.smk).
"""

import logging

from mcfbench.storage.frames import load_frames
from mcfbench.storage.records import read_record
from mcfbench.studies.matrix.plan import picture_runs
from mcfbench.studies.matrix.plots import picture_grid

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
plan = sm.params.plan
entries = {key: (read_record(record), load_frames(frames))
           for key, (record, frames) in picture_runs(plan).items()}
picture_grid(entries, [sm.output.png, sm.output.pdf], list(plan["problems"]), plan["schemes"])
logging.info("wrote %s", ", ".join(sm.output))
