"""Rule run_scheme: one scheme on one sphere level -> its run record.

``params.settings``: :func:`mcfbench.studies.convergence.record_settings`
(scheme, problem, level, tau, t_final, rtol, source hashes); the job is
:func:`mcfbench.studies.convergence.job`, the record written by
:func:`mcfbench.storage.records.write_record` (fields of
:class:`mcfbench.storage.records.RunResult`, settings, provenance, checksum).
"""

from mcfbench.storage.logs import setup_logging
from mcfbench.storage.memory import tune_malloc
from mcfbench.studies.convergence.job import job

tune_malloc()  # before any flow allocates: halves the wall time of level 5

sm = snakemake  # noqa: F821
job(dict(sm.params.settings), str(sm.output[0]), setup_logging(sm.log[0]))
