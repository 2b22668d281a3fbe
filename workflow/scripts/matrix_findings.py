"""findings.md of the benchmark matrix, from the summary table only.

Called by rule ``matrix_findings`` (workflow/rules/matrix.smk); the text is
:func:`mcfbench.studies.matrix.findings.matrix_findings` of ``summary.csv``.
"""

import logging

from mcfbench.studies.matrix import findings as matrix_findings

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO, force=True)  # noqa: F821
text = matrix_findings.findings(snakemake.input.summary, snakemake.output[0],  # noqa: F821
                                snakemake.params.plan, snakemake.input.table)  # noqa: F821
logging.info("\n%s", text)
