"""Rule beyond_tables: the tables of the study beyond Table 3.1 from its records.

The job is :func:`mcfbench.studies.beyond.aggregate`: every record checked
first; ``levels``, ``stability``, ``time_convergence``, ``space_convergence``,
``integrators`` (CSV, Markdown, LaTeX each), ``t_monitor.csv`` (the T monitor at every time
level) and ``beyond.json`` (provenance), written together.
"""

from mcfbench.storage.logs import setup_logging
from mcfbench.studies.beyond.aggregate import aggregate

sm = snakemake  # noqa: F821
inputs = {study: [str(p) for p in sm.input[study]]
          for study in ("levels", "long_time", "space", "time")}
aggregate(dict(sm.params.expected), inputs, dict(sm.params.beyond), dict(sm.params.settings),
          list(sm.params.paper_schemes), sm.output, setup_logging(sm.log[0]))
