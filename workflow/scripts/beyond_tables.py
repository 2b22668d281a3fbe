"""Rule beyond_tables: the tables of the study beyond Table 3.1 from its records.

The job is :func:`mcfbench.studies.beyond.aggregate`: every record of its specs
(:func:`mcfbench.studies.beyond.plan.beyond_specs`) read from the run store and
checked first; ``levels``, ``stability``, ``time_convergence``, ``space_convergence``,
``integrators`` (CSV, Markdown, LaTeX each), ``t_monitor.csv`` (the T monitor at every
time level) and ``beyond.json`` (provenance), written together.
"""

from mcfbench.pipeline import code_digests
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.beyond.aggregate import aggregate
from mcfbench.studies.beyond.plan import TABLE_STUDIES, beyond_specs

sm = snakemake  # noqa: F821
plan = dict(sm.params.beyond)
specs = {study: part for study, part in beyond_specs(plan, dict(sm.params.table)).items()
         if study in TABLE_STUDIES}
digests = code_digests([s for part in specs.values() for s in part.values()])
aggregate(specs, digests, plan, dict(sm.params.settings), list(sm.params.paper_schemes),
          sm.output, setup_logging(sm.log[0]))
