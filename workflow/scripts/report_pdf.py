"""The reproduction report as a PDF: ``paper/reproduction.tex`` with pdflatex.

Called by rule ``report_pdf`` (workflow/rules/report.smk; not part of the
default pipeline), or by hand from the repository root:

    python workflow/scripts/report_pdf.py [results/paper/reproduction.pdf]

The template ``\\input``s the fragments of ``results/paper/tex/`` (written
by report.py) and ``results/tables/convergence.tex``, and includes the PDF
figures from ``results/figures/``; pdflatex runs twice (references) from the
repository root in a scratch folder next to the output. Needs pdflatex with
booktabs, graphicx, amssymb and hyperref (TeX Live: texlive-latex-recommended).
"""

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from run_records import setup_logging  # noqa: E402  (first: sys.path)

TEMPLATE = Path("paper/reproduction.tex")
RUNS = 2


def build_pdf(output, template=TEMPLATE, log=None, pdflatex="pdflatex"):
    """Compile ``template`` (paths relative to the working directory, the
    repository root) into ``output``. Raises RuntimeError with pdflatex's
    last lines if a run fails, or if pdflatex is not installed."""
    exe = shutil.which(pdflatex)
    if exe is None:
        raise RuntimeError(f"{pdflatex} not found: the PDF of the report needs a TeX "
                           "installation (e.g. Debian's texlive-latex-recommended); the "
                           "HTML and Markdown reports do not")
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=".pdf-", dir=output.parent) as build:
        command = [exe, "-interaction=nonstopmode", "-halt-on-error", "-file-line-error",
                   f"-output-directory={build}", f"-jobname={output.stem}", str(template)]
        for run in range(RUNS):
            proc = subprocess.run(command, capture_output=True, text=True, timeout=300)
            if log:
                log.info("pdflatex run %d: exit %d", run + 1, proc.returncode)
            if proc.returncode != 0:
                tail = "\n".join(proc.stdout.splitlines()[-30:])
                raise RuntimeError(f"pdflatex failed on {template}:\n{tail}")
        shutil.copyfile(Path(build) / f"{output.stem}.pdf", output)
    if log:
        log.info("wrote %s", output)
    return output


def main(output, template, log_file):
    log = setup_logging(log_file)
    try:
        build_pdf(output, template, log)
    except RuntimeError as err:
        log.error("%s", err)
        return 1
    return 0


if __name__ == "__main__":
    if "snakemake" in globals():
        sm = snakemake  # noqa: F821
        sys.exit(main(sm.output.pdf, sm.input.template, sm.log[0]))
    out = sys.argv[1] if len(sys.argv) > 1 else "results/paper/reproduction.pdf"
    sys.exit(main(out, TEMPLATE, "results/logs/report_pdf.log"))
