"""The figures of the benchmark matrix (mcfbench.studies.matrix.plots).

Called by rule ``matrix_plots`` (workflow/rules/matrix.smk): error and cost
against h from the long table, mesh quality over time from the records' series
(the picture grid: ``matrix_pictures.py``).
"""

import logging

from mcfbench.pipeline import code_digests
from mcfbench.storage.run_store import read_runs
from mcfbench.studies.matrix.plan import planned_specs
from mcfbench.studies.matrix.plots import error_figure, quality_figure, work_precision_figure
from mcfbench.studies.matrix.tables import read_long_table

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
plan, out = sm.params.plan, sm.output
problems, schemes = list(plan["problems"]), plan["schemes"]
table = read_long_table(sm.input.table)
error_figure(table, [out.errors_png, out.errors_pdf], problems, schemes)
work_precision_figure(table, [out.work_precision_png, out.work_precision_pdf], problems, schemes)
records = read_runs(code_digests(planned_specs(plan).values()))
quality_figure(list(records.values()), [out.quality_png, out.quality_pdf], problems, schemes)
logging.info("wrote %s", ", ".join(out))
