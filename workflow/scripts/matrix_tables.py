"""The tables of the benchmark matrix from its run records.

Called by rule ``matrix_tables`` (workflow/rules/matrix.smk): every record of the
plan's specs is read from the run store and checked against its spec key and code
digest (stale or edited records are refused), then
:func:`mcfbench.studies.matrix.aggregate` writes ``matrix.csv``, one table per
problem and the summary.
"""

import logging
from pathlib import Path

from mcfbench.pipeline import code_digests
from mcfbench.studies.matrix.aggregate import aggregate
from mcfbench.studies.matrix.plan import planned_specs

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
expected = code_digests(planned_specs(sm.params.plan).values())
table, summary = aggregate(expected, sm.params.plan, Path(sm.output[0]).parent)
logging.info("%d runs, %d rows; summary:\n%s", len(expected), len(table), summary.to_string())
