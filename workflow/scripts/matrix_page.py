"""The results page of the benchmark matrix (mcfbench.studies.matrix.page).

Called by rule ``matrix_page`` (workflow/rules/matrix.smk): one self-contained
HTML file, ``results/matrix/index.html``, of the tables (sortable), the
figures (as data URIs) and the findings, written atomically.
"""

import logging
from pathlib import Path

from mcfbench.studies.matrix.page import write_matrix_page

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
size = write_matrix_page(Path(sm.input.table).parents[1], sm.output[0], sm.params.plan)
logging.info("wrote %s (%d bytes)", sm.output[0], size)
