"""Rule compile_kernels: every numba kernel compiled into the cache once.

The job is :func:`mcfbench.pipeline.compile_job`; the run rules take its
output as an ``ancient`` input, so they start after it and load the
kernels instead of each compiling them.
"""

from mcfbench.pipeline import compile_job
from mcfbench.storage.logs import setup_logging

sm = snakemake  # noqa: F821
compile_job(sm.params.threads, str(sm.output[0]), setup_logging(sm.log[0]))
