"""Rule reproduction_report: the report from the result files (mcfbench.presentation.report.build).

Writes ``reproduction.md``, ``.html`` (self-contained), ``.json`` (every check)
and the LaTeX fragments under ``tex/``. Sources: the inputs of the rule
(results/, paper/, ddfv/README.md) and whatever results/beyond/ holds. By
hand: ``mcfbench report``.
"""

from pathlib import Path

from mcfbench.presentation.report import build, default_outputs
from mcfbench.presentation.report_inputs import Sources
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.figure_experiments import EXPERIMENTS

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
results = Path(sm.input.table).parents[1]            # results/tables/convergence.csv
sources = Sources(results=results, paper=Path(sm.input.checks).parent, readme=sm.input.readme,
                  out=Path(sm.output.html).parent, beyond=results / "beyond",
                  beyond_targets=tuple(sm.params.beyond_targets),
                  figures=tuple(sm.params.figures), experiments=EXPERIMENTS)
build(sources, {key: sm.output[key] for key in default_outputs(".")}, log=log)
