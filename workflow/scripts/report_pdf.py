"""Rule report_pdf: ``paper/reproduction.tex`` with the report's fragments as a PDF.

Needs pdflatex (booktabs, graphicx, amssymb, hyperref); see
:func:`mcfbench.presentation.documents.build_pdf`.
"""

from mcfbench.presentation.documents import build_pdf
from mcfbench.storage.logs import setup_logging

sm = snakemake  # noqa: F821
build_pdf(sm.output.pdf, sm.input.template, setup_logging(sm.log[0]))
