"""Rule convergence_table: Table 3.1 from the run records (CSV, Markdown, LaTeX, provenance).

The job is :func:`mcfbench.studies.convergence.aggregate`: every record of its specs
checked first (``params.expected``: :meth:`mcfbench.pipeline.RunStore.expected`), one
bad or stale record stops it with a message naming the file; all four files written
together.
"""

from mcfbench.pipeline import expected_runs
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.convergence.aggregate import aggregate

sm = snakemake  # noqa: F821
aggregate(expected_runs(sm.params.expected), list(sm.params.schemes), list(sm.params.levels),
          dict(sm.params.settings), sm.output, setup_logging(sm.log[0]))
