"""One run of the benchmark matrix: record and first/last frame.

Called by rule ``matrix_run`` (workflow/rules/matrix.smk); the settings come
from ``params.settings`` (:func:`mcfbench.studies.matrix.run_settings`). The work is
:func:`mcfbench.studies.matrix.job`.
"""

import os

# Timed runs are single-threaded: BLAS reads these when numpy is first imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
             "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

from mcfbench.studies import matrix  # noqa: E402

matrix.job(snakemake.params.settings, snakemake.output.record,  # noqa: F821
           snakemake.output.frames, snakemake.log[0])  # noqa: F821
