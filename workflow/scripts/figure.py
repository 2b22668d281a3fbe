"""Rule figure: run the experiment of one figure (mcfbench.studies.figures) and draw it.

Writes the figure (PNG, PDF), the kept frames (a folder, one frames file per
run), the per-step mesh diagnostics (CSV, plot) and the figure's record
(JSON): see :func:`mcfbench.studies.figures.job`. A run that breaks down
keeps its frames; the job still succeeds.
"""

from mcfbench.storage.logs import setup_logging
from mcfbench.storage.memory import tune_malloc
from mcfbench.studies.figures import FIGURE_OUTPUTS
from mcfbench.studies.figures.job import job

tune_malloc()  # before any flow allocates

sm = snakemake  # noqa: F821
job(sm.wildcards.figure, {key: str(sm.output[key]) for key in FIGURE_OUTPUTS},
    setup_logging(sm.log[0]))
