"""Rule beyond_time: time convergence of one scheme on one mesh -> a JSON record.

``params.settings``: :meth:`mcfbench.pipeline.Pipeline.time_settings`; the job
is :func:`mcfbench.pipeline.time_job` (:func:`mcfbench.running.run.time_convergence`,
any scheme of the registry).
"""

from mcfbench.pipeline import time_job
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.memory import tune_malloc

tune_malloc()  # before any flow allocates

sm = snakemake  # noqa: F821
time_job(dict(sm.params.settings), str(sm.output[0]), setup_logging(sm.log[0]))
