"""Beyond Table 3.1: level 6 and beyond, the scheme variants, the long-time, time and
space studies of the sphere (``workflow/rules/beyond.smk``; config key ``beyond``).

The study's modules:

* :mod:`.plan`: the config key ``beyond`` checked against the registry and the
  Table 3.1 keys it builds on (:func:`mcfbench.studies.convergence.plan.plan`);
  :func:`~.plan.beyond_runs`, every record of the study with its settings;
* :mod:`.job`: one run of the study: the time study of one scheme
  (:func:`mcfbench.running.run.time_convergence`) or one run on one level
  (:func:`mcfbench.studies.convergence.job.job`);
* :mod:`.aggregate`: the records into the tables and the T-monitor series
  (:mod:`.tables`);
* :mod:`.findings`: the verdicts from the tables only (stable schemes, the
  finest common level, the ranking), worded in ``findings.md``
  (:func:`~.findings.write_findings`).
"""
