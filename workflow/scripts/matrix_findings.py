"""findings.md of the benchmark matrix, from its tables only.

Called by rule ``matrix_findings`` (workflow/rules/matrix.smk); the text is
:func:`mcfbench.studies.matrix.findings.matrix_findings` of ``matrix.csv`` and
``summary.csv``.
"""

import logging

from mcfbench.studies.matrix import findings as matrix_findings

logging.basicConfig(filename=snakemake.log[0], level=logging.INFO, force=True)  # noqa: F821
text = matrix_findings.findings(snakemake.input.summary, snakemake.input.table,  # noqa: F821
                                snakemake.output[0], snakemake.params.plan)  # noqa: F821
logging.info("\n%s", text)
