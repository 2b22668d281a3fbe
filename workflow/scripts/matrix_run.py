"""The series of one batch of the benchmark matrix (several schemes on one
problem, or one heavy series alone): a record and first/last frame per run, a
log per series.

Called by the rules ``matrix_run_{problem}_batch{k}`` (workflow/rules/matrix.smk);
the settings shared by the problem's runs come from ``params.settings``
(:func:`mcfbench.studies.matrix.plan.problem_settings`), each run's scheme and
level from its record path. The work is
:func:`mcfbench.studies.matrix.job.batch_job`.
"""

import os

# Timed runs are single-threaded: BLAS reads these when numpy is first imported.
from mcfbench.storage.provenance import BLAS_THREAD_VARIABLES  # imports no numpy

os.environ.update(dict.fromkeys((*BLAS_THREAD_VARIABLES, "NUMBA_NUM_THREADS"), "1"))

from mcfbench.studies.matrix import job as matrix_job  # noqa: E402

matrix_job.batch_job(snakemake.params.settings, snakemake.output.records,  # noqa: F821
                     snakemake.output.frames, list(snakemake.log))  # noqa: F821
