"""Rules beyond_run and beyond_time: one run of the beyond study -> its record.

``params.settings``: :func:`mcfbench.studies.beyond.study_settings` (one scheme
on one level of the long-time or space study) or
:func:`mcfbench.studies.beyond.time_settings` (the time study of one scheme);
the job is :func:`mcfbench.studies.beyond.job`.
"""

from mcfbench.storage.logs import setup_logging
from mcfbench.storage.memory import tune_malloc
from mcfbench.studies.beyond.job import job

tune_malloc()  # before any flow allocates

sm = snakemake  # noqa: F821
job(dict(sm.params.settings), str(sm.output[0]), setup_logging(sm.log[0]))
