"""Rule beyond_findings: the findings of the beyond study in words
(:func:`mcfbench.studies.beyond.write_findings`: the verdicts of
:func:`mcfbench.studies.beyond.findings` in words). Every number and verdict is read from
the tables: nothing is typed by hand.
"""

from mcfbench.storage.logs import setup_logging
from mcfbench.studies.beyond.findings import write_findings

sm = snakemake  # noqa: F821
write_findings({key: sm.input[key]
                for key in ("levels", "stability", "time", "space", "integrators")},
               dict(sm.params.beyond), list(sm.params.paper_schemes),
               {"t_final": sm.params.t_final, "tau_level_1": sm.params.tau_level_1},
               sm.output[0], setup_logging(sm.log[0]))
