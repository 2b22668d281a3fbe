"""One scheme on one problem's refinement series in the benchmark matrix: a
record and first/last frame per level.

Called by the rules ``matrix_run_{problem}`` (workflow/rules/matrix.smk); the
settings of the series come from ``params.series``
(:func:`mcfbench.studies.matrix.plan.series_settings`), each run's level from
its record path. The work is
:func:`mcfbench.studies.matrix.series_job`.
"""

import os

# Timed runs are single-threaded: BLAS reads these when numpy is first imported.
from mcfbench.storage.provenance import BLAS_THREAD_VARIABLES  # imports no numpy

os.environ.update(dict.fromkeys((*BLAS_THREAD_VARIABLES, "NUMBA_NUM_THREADS"), "1"))

from mcfbench.studies.matrix import job as matrix_job  # noqa: E402

matrix_job.series_job(snakemake.params.series, snakemake.output.records,  # noqa: F821
                      snakemake.output.frames, snakemake.log[0])  # noqa: F821
