"""The figures of the benchmark matrix (mcfbench.studies.matrix.plots).

Called by rule ``matrix_plots`` (workflow/rules/matrix.smk): error against h
from the long table, mesh quality over time from the records' series, and
the picture grid of final surfaces from the saved frames.
"""

import logging

from mcfbench.storage.frames import load_frames
from mcfbench.storage.records import read_record, read_records
from mcfbench.studies.matrix.plan import picture_runs, planned_runs
from mcfbench.studies.matrix.plots import (
    error_figure,
    picture_grid,
    quality_figure,
    work_precision_figure,
)
from mcfbench.studies.matrix.tables import read_long_table

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
plan, out = sm.params.plan, sm.output
problems, schemes = list(plan["problems"]), plan["schemes"]
table = read_long_table(sm.input.table)
error_figure(table, [out.errors_png, out.errors_pdf], problems, schemes)
work_precision_figure(table, [out.work_precision_png, out.work_precision_pdf], problems, schemes)
records = read_records(planned_runs(plan, sm.params.code))
quality_figure(list(records.values()), [out.quality_png, out.quality_pdf], problems, schemes)
entries = {key: (read_record(record), load_frames(frames))
           for key, (record, frames) in picture_runs(plan).items()}
picture_grid(entries, [out.pictures_png, out.pictures_pdf], problems, schemes)
logging.info("wrote %s", ", ".join(out))
