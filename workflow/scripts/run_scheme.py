"""Rules run_scheme and beyond_run: one scheme on one sphere level -> its run record.

``params.settings``: :meth:`mcfbench.pipeline.Pipeline.run_settings` (scheme,
problem, level, tau, t_final, rtol, source hashes); the record is written by
:func:`mcfbench.storage.records.write_record` (fields of
:class:`mcfbench.storage.records.RunResult`, settings, provenance, checksum).
"""

from mcfbench.pipeline import run_job
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.memory import tune_malloc

tune_malloc()  # before any flow allocates: halves the wall time of level 5

sm = snakemake  # noqa: F821
run_job(dict(sm.params.settings), str(sm.output[0]), setup_logging(sm.log[0]))
