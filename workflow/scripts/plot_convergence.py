"""Rule convergence_figure: L2 error against h for every scheme (mcfbench.presentation.plots)."""

import pandas as pd

from mcfbench.presentation.plots import convergence_figure
from mcfbench.storage.atomic import write_files
from mcfbench.storage.logs import setup_logging

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
fig = convergence_figure(pd.read_csv(sm.input.csv), float(sm.params.t_final))
write_files({str(sm.output.png): fig, str(sm.output.pdf): fig})
log.info("wrote %s, %s", sm.output.png, sm.output.pdf)
