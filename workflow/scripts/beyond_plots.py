"""Rule beyond_figures: the figures of the beyond study from its tables (mcfbench.presentation.plots)."""

import pandas as pd

from mcfbench.presentation.plots import beyond_figures
from mcfbench.storage.atomic import write_files
from mcfbench.storage.logs import setup_logging

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
tables = {key: pd.read_csv(sm.input[key])
          for key in ("levels", "stability", "t_monitor", "time", "space")}
figures = beyond_figures(tables["levels"], tables["stability"], tables["t_monitor"],
                         tables["time"], tables["space"],
                         dict(sm.params.beyond),
                         float(sm.params.t_final))
write_files({str(sm.output[f"{name}_{ext}"]): fig
             for name, fig in figures.items() for ext in ("png", "pdf")})
log.info("wrote %s", ", ".join(str(path) for path in sm.output))
