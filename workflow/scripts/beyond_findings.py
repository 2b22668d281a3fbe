"""Rule beyond_findings: the findings of the beyond study in words (mcfbench.presentation.beyond_findings).

Every number and verdict is read from the tables: nothing is typed by hand.
"""

import pandas as pd

from mcfbench.presentation.beyond_findings import beyond_findings as findings
from mcfbench.running.integrators import INTEGRATORS
from mcfbench.storage.atomic import write_files
from mcfbench.storage.logs import setup_logging

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
tables = [pd.read_csv(sm.input[key]) for key in ("levels", "stability", "time", "space")]
text = findings(*tables, list(sm.params.beyond["schemes"]), list(sm.params.paper_schemes),
                float(sm.params.t_final), float(sm.params.tau_level_1),
                integrators=pd.read_csv(sm.input["integrators"]),
                orders={name: cls.order for name, cls in INTEGRATORS.items()})
write_files({str(sm.output[0]): text})
log.info("wrote %s", sm.output[0])
