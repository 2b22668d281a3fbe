"""The tables of the benchmark matrix from its run records.

Called by rule ``matrix_tables`` (workflow/rules/matrix.smk): every record is
read and checked against the settings of its run (stale or edited records are
refused), then :func:`mcfbench.studies.matrix.aggregate` writes ``matrix.csv``, one
table per problem and the summary.
"""

import logging
from pathlib import Path

from mcfbench.studies.matrix.aggregate import aggregate
from mcfbench.studies.matrix.plan import planned_runs

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO, force=True)  # noqa: F821
expected = planned_runs(snakemake.params.plan, snakemake.params.code)  # noqa: F821
table, summary = aggregate(expected, snakemake.params.plan,  # noqa: F821
                           Path(snakemake.output[0]).parent)  # noqa: F821
logging.info("%d runs, %d rows; summary:\n%s", len(expected), len(table), summary.to_string())
