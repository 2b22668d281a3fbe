"""Beyond Table 3.1: level 6 and beyond, the scheme variants, the long-time, time and
space studies of the sphere (``workflow/rules/beyond.smk``; config key ``beyond``).

The study's modules:

* :mod:`.plan`: the config key ``beyond`` checked against the registry and the
  Table 3.1 keys it builds on (:func:`mcfbench.studies.convergence.plan.plan`);
  :func:`~.plan.beyond_specs`, the spec of every run of the study (the time study's
  too: one run per time step and the reference's);
* :mod:`.aggregate`: the records into the tables and the T-monitor series
  (:mod:`.tables`); the time study's errors from the saved final states
  (:func:`~.aggregate.time_records`);
* :mod:`.scaling`: cost against size, the CPU seconds per step and the peak
  memory of its runs (every scheme of the registry unless ``beyond.scaling.schemes``
  narrows it) against their unknowns with fitted slopes;
* :mod:`.findings`: the verdicts from the tables only (stable schemes, the
  finest common level, the ranking), worded in ``findings.md``
  (:func:`~.findings.write_findings`).
"""

ROOT = "results/beyond"
"""The folder of the study's outputs (its runs are specs in the run store,
:mod:`mcfbench.storage.run_store`; its level runs are Table 3.1's)."""

TABLES = f"{ROOT}/tables"
"""``{name}.csv/.md/.tex`` of :data:`TABLE_NAMES`, ``t_monitor.csv``, ``beyond.json``
(provenance), ``records.json`` (the check of the records)."""

TABLE_NAMES = ("levels", "stability", "time_convergence", "space_convergence", "integrators")

SCALING = f"{TABLES}/scaling"
"""The scaling study's own outputs (rule ``beyond_scaling``, its runs only):
``scaling.csv/.md/.tex`` (one row per scheme), ``scaling_points.csv`` (one row
per run), ``scaling.json`` (provenance); its figure :data:`SCALING_FIGURE`."""

SCALING_FIGURE = f"{ROOT}/figures/scaling"
"""``scaling.png/.pdf``: cost against size."""

FIGURES = f"{ROOT}/figures"
"""``{name}.png/.pdf`` of :data:`FIGURE_NAMES`."""

FIGURE_NAMES = ("levels", "t_monitor", "time_convergence", "space_convergence")

FINDINGS = f"{ROOT}/findings.md"
