"""Rule reproduction_report: the report from the result files (mcfbench.studies.report.page.build).

Writes ``reproduction.md``, ``.html`` (self-contained), ``.json`` (every check)
and the LaTeX fragments under ``tex/``. Sources: the inputs of the rule
(results/, paper/, ddfv/README.md) and whatever results/beyond/ holds. By
hand: ``mcfbench report``.
"""

from pathlib import Path

from mcfbench.storage.logs import setup_logging
from mcfbench.studies.figures.experiments import EXPERIMENTS
from mcfbench.studies.report.inputs import Sources
from mcfbench.studies.report.page import build, default_outputs

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
results = Path(sm.input.table).parents[1]            # results/tables/convergence.csv
sources = Sources(results=results, paper=Path(sm.input.checks).parent, readme=sm.input.readme,
                  out=Path(sm.output.html).parent, beyond=results / "beyond",
                  beyond_targets=tuple(sm.params.beyond_targets),
                  figures=tuple(sm.params.figures), experiments=EXPERIMENTS)
build(sources, {key: sm.output[key] for key in default_outputs(".")}, log=log)
