"""Rule figure: run the experiment of one figure (mcfbench.studies.figures) and draw it.

Writes the figure (PNG, PDF), the kept frames (npz), the per-step mesh
diagnostics (CSV, plot) and the figure's record (JSON): see
:func:`mcfbench.pipeline.figure_job`. A run that breaks down keeps its
frames; the job still succeeds.
"""

from mcfbench.pipeline import FIGURE_OUTPUTS, figure_job
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.memory import tune_malloc

tune_malloc()  # before any flow allocates

sm = snakemake  # noqa: F821
figure_job(sm.wildcards.figure, {key: str(sm.output[key]) for key in FIGURE_OUTPUTS},
           setup_logging(sm.log[0]))
