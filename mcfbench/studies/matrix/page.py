"""The results page of the benchmark matrix: one self-contained HTML file
(``results/matrix/index.html``) of the summary, one sortable table of runs per
problem, the figures as data URIs and the findings.

Every table on the page sorts by any column: a click on a header sorts
ascending, a second click descending (stable: rows that tie keep their order;
empty cells last either way). A numeric column sorts by the exact value
(``data-sort``, the shortest round-trip form of the float), not by the shown
text. The URL fragment ``#sort=COLUMN`` (``#sort=-COLUMN``: descending)
clicks that column of every table that has it once the page has loaded, so a
sorted view can be linked, and a headless browser can be checked
(``tests/workflow/test_results_page.py``). Nothing is fetched at view time:
no CDN, no font, no script but the page's own.
"""

import html as _html
import re
from pathlib import Path

import markdown as _markdown

from mcfbench.presentation.documents import (
    MARKDOWN_EXTENSIONS,
    data_uri,
    embed_images,
    environment,
    external_references,
    unlink_files,
)
from mcfbench.presentation.formats import sci, sig
from mcfbench.presentation.tables import Table, html
from mcfbench.studies.matrix.tables import (
    is_error,
    main_runs,
    read_long_table,
    read_summary,
    TIMING_NOTE,
)

TEMPLATES = Path(__file__).with_name("templates")

# (name, caption) of the figures of rules matrix_plots and matrix_pictures, in page order
PAGE_FIGURES = (
    ("errors", ("Error of each problem's main metric against the mesh size h, every "
                "scheme; slope-2 guides.")),
    ("work_precision", ("Work-precision: the main error of every run against its CPU "
                        "seconds (one core, the problem's solver rule).")),
    ("quality", "Smallest angle (and the DDFV T monitor) against time, per problem."),
    ("pictures", "The final surfaces, scheme x problem (coarsest level)."),
)

# columns of a problem's table of runs: (column of matrix.csv, header, format)
RUN_COLUMNS = (
    ("scheme", "scheme", None), ("level", "level", None), ("h", "h", sig),
    ("tau", "tau", sig), ("steps_done", "steps done", None), ("steps", "steps", None),
    ("value", "value", sci), ("eoc", "EOC", lambda x: sig(x, 3)),
    ("status", "status", None), ("t_failed", "t failed", lambda x: sig(x, 4)),
    ("min_angle", "min angle", sig), ("max_flipped", "flipped", lambda x: sig(x, 3)),
    ("t_min_barycentric", "T monitor", sig), ("iterations", "iterations", None),
    ("cpu_seconds", "CPU s", sig),
)

# columns of the summary (summary.csv)
SUMMARY_COLUMNS = (
    ("problem", "problem", None), ("scheme", "scheme", None), ("metric", "metric", None),
    ("levels", "levels", None), ("runs_ok", "runs ok", None), ("runs", "runs", None),
    ("eoc", "EOC", lambda x: sig(x, 3)), ("eoc_levels", "EOC levels", None),
    ("finest_level", "finest level", lambda x: sig(x, 3)),
    ("finest_value", "finest value", sci), ("status", "status", None),
    ("t_failed", "t failed", lambda x: sig(x, 4)), ("min_angle", "min angle", sig),
    ("t_min_barycentric", "T monitor", sig), ("cpu_seconds", "CPU s (finest)", sig),
)


def print_width(png):
    """The width of a PNG at print size in CSS pixels (96 to the inch), from the
    resolution matplotlib wrote into it: the page shows a figure at this width, so
    its text has the size in points it was drawn with
    (:data:`mcfbench.presentation.plots.SMALLEST_TEXT` at least)."""
    from PIL import Image

    with Image.open(png) as image:
        dpi = float(image.info.get("dpi", (96.0, 96.0))[0]) or 96.0
        return round(image.width * 96.0 / dpi)


def html_table(frame, columns, table_id, caption=""):
    """The ``columns`` (``(name, header, format)``) of ``frame`` as a sortable HTML
    table (:func:`mcfbench.presentation.tables.html`), ``data-column`` the names."""
    table = Table.of_frame(frame, columns, caption=caption)
    return html(table, table_id, [name for name, _, _ in columns if name in frame.columns])


def findings_html(text, base, shift=2):
    """``findings.md`` as HTML (the report's Markdown extensions), headings
    ``shift`` levels down (its title under the page's section heading), images
    embedded from ``base``, links to files as text."""
    body = _markdown.Markdown(extensions=MARKDOWN_EXTENSIONS).convert(text)
    body = re.sub(r"<(/?)h([1-6])\b",
                  lambda m: f"<{m[1]}h{min(6, int(m[2]) + shift)}", body)
    return unlink_files(embed_images(body, base))


def _problem_section(table, problem):
    from mcfbench.running.problems import PROBLEMS

    runs, metric = main_runs(table, problem)
    p = PROBLEMS.get(problem)
    notes = [f"Main metric: <code>{_html.escape(metric)}</code>"
             + (" (an error: EOC (3.1) between consecutive levels)." if is_error(metric)
                else " (no exact value: no EOC).")]
    if p is not None:
        notes.append(_html.escape(f"{p.label}. {p.description}".strip()))
        if getattr(p, "exact", None):
            notes.append(_html.escape(f"Exact answer: {p.exact}."))
    return {"problem": problem, "metric": metric, "notes": notes,
            "table": html_table(runs, RUN_COLUMNS, f"runs-{problem}",
                                f"{problem}: every run, value of {metric}")}


def matrix_page(matrix_dir, plan=None, title="Benchmark matrix: results"):
    """The HTML of the results page of the matrix in ``matrix_dir`` (its
    ``tables/matrix.csv``, ``tables/summary.csv``, ``figures/*.png`` and
    ``findings.md``; a missing figure or findings file is named on the page).

    Parameters
    ----------
    matrix_dir : path
        ``results/matrix`` of a pipeline run.
    plan : dict, optional
        :func:`mcfbench.studies.matrix.plan` of the run: problem and scheme
        order (default: that of ``matrix.csv``).
    """
    from mcfbench.running.schemes import scheme_label

    root = Path(matrix_dir)
    table = read_long_table(root / "tables" / "matrix.csv")
    problems = [p for p in (plan["problems"] if plan else dict.fromkeys(table["problem"]))
                if p in set(table["problem"])]
    schemes = list(plan["schemes"]) if plan else list(dict.fromkeys(table["scheme"]))
    labels = {s: scheme_label(s) for s in schemes}
    summary = read_summary(root / "tables" / "summary.csv")
    figures = []
    for name, caption in PAGE_FIGURES:
        path = root / "figures" / f"{name}.png"
        figures.append({"name": name, "caption": caption,
                        "src": data_uri(path) if path.is_file() else None,
                        "width": print_width(path) if path.is_file() else None,
                        "path": f"figures/{name}.png"})
    findings = root / "findings.md"
    context = {
        "title": title,
        "schemes": [{"name": s, "label": labels[s]} for s in schemes],
        "problems": problems,
        "runs": len(table.drop_duplicates(["scheme", "problem", "level"])),
        "summary": html_table(summary, SUMMARY_COLUMNS, "summary",
                              "problem x scheme: the main metric"),
        "sections": [_problem_section(table, p) for p in problems],
        "figures": figures,
        "findings": findings_html(findings.read_text(), root) if findings.is_file() else None,
        "timing_note": TIMING_NOTE,
    }
    html = environment(TEMPLATES).get_template("page.html.j2").render(**context)
    outside = external_references(html)
    if outside:
        raise ValueError(f"the results page would load {outside[:3]} at view time; "
                         "it must be self-contained")
    return html


def write_matrix_page(matrix_dir, out, plan=None):
    """Write :func:`matrix_page` to ``out`` atomically; returns its size in bytes."""
    from mcfbench.storage.atomic import write_text

    html = matrix_page(matrix_dir, plan)
    write_text(out, html)
    return len(html.encode("utf-8"))
