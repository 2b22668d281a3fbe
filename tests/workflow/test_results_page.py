"""The results page of the matrix (mcfbench.studies.matrix.page) in a real
headless browser: a tiny matrix (cotan and ddfv; sphere levels 1-2, catenoid
level 1) built through the study's job function, tables, findings and plots as
the rules build them, then the page loaded in headless Chromium with
``#sort=COLUMN`` (the page clicks that header once it has loaded, twice for
``-COLUMN``), its DOM dumped, and the order of the rows compared with pandas'
stable sort of the same table (empty cells last).

Chromium is Debian's ``chromium`` package (``.ci/run`` installs it). Without
it these tests are skipped, and fail when ``CI`` is set.
"""

import os
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import pytest

from mcfbench.presentation.documents import external_references
from mcfbench.storage.frames import load_frames
from mcfbench.studies.matrix.page import PAGE_FIGURES, write_matrix_page
from mcfbench.studies.matrix.tables import main_runs, read_long_table, read_summary

pytestmark = pytest.mark.e2e

BROWSERS = ("chromium", "chromium-browser", "google-chrome")
# one page load per fragment; each sorts every table that has the column
# (iterations: 4, 26, 8, 45 on the sphere, in another order as text than as numbers)
FRAGMENTS = ("value", "-value", "scheme", "-level", "iterations", "-t_min_barycentric",
             "t_failed", "-cpu_seconds", "status", "-eoc")


def _in_ci():
    return os.environ.get("CI", "").strip().lower() not in ("", "0", "false", "no")


@pytest.fixture(scope="module")
def browser():
    exe = next((path for name in BROWSERS if (path := shutil.which(name))), None)
    if exe is None:
        message = ("headless Chromium not found (Debian: apt-get install -y chromium); "
                   "the results page is not checked in a browser")
        if _in_ci():
            pytest.fail(message + " - CI is set, so this is an error")
        pytest.skip(message)
    return exe


@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """``(matrix folder, plan)`` of a tiny matrix with its tables, findings,
    figures and ``index.html``."""
    from mcfbench.running.problems import PROBLEMS
    from mcfbench.running.batch import compute
    from mcfbench.storage.run_store import frames_path, read_run, read_runs
    from mcfbench.studies.matrix import aggregate as matrix_aggregate
    from mcfbench.studies.matrix import findings as matrix_findings
    from mcfbench.studies.matrix import plan as matrix_plan
    from mcfbench.studies.matrix.plots import (
        error_figure,
        picture_grid,
        quality_figure,
        work_precision_figure,
    )

    root = tmp_path_factory.mktemp("matrix")
    levels = {"sphere": [1, 2], "catenoid": [1]}
    plan = matrix_plan.plan({"schemes": ["cotan", "ddfv"],
                             "problems": {p: levels.get(p, []) for p in PROBLEMS}})
    store = str(root / "runs")
    runs = dict.fromkeys(matrix_plan.planned_specs(plan).values(), "test")
    for spec in runs:
        compute(spec, "test", store)
    table, _ = matrix_aggregate.aggregate(runs, plan, root / "tables", store)
    matrix_findings.findings(root / "tables" / "summary.csv", root / "tables" / "matrix.csv",
                             root / "findings.md", plan)
    problems, schemes, figures = list(plan["problems"]), plan["schemes"], root / "figures"
    error_figure(table, [figures / "errors.png"], problems, schemes)
    work_precision_figure(table, [figures / "work_precision.png"], problems, schemes)
    quality_figure(list(read_runs(runs, root=store).values()), [figures / "quality.png"],
                   problems, schemes)
    entries = {key: (read_run(spec, "test", store), load_frames(frames_path(spec, store)))
               for key, spec in matrix_plan.picture_specs(plan).items()}
    picture_grid(entries, [figures / "pictures.png"], problems, schemes)
    size = write_matrix_page(root, root / "index.html", plan)
    assert size == (root / "index.html").stat().st_size
    return root, plan


class _Tables(HTMLParser):
    """``{table id: {"columns": [...], "sorted": {column: aria-sort}, "rows": [(data-row,
    [cell texts])]}}`` of the sortable tables of a document."""

    def __init__(self):
        super().__init__()
        self.tables, self._table, self._cell = {}, None, None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "table" and "sortable" in (attrs.get("class") or ""):
            self._table = self.tables.setdefault(attrs["id"], {"columns": [], "sorted": {},
                                                               "rows": []})
        elif self._table is None:
            return
        elif tag == "th":
            self._table["columns"].append(attrs["data-column"])
            self._table["sorted"][attrs["data-column"]] = attrs.get("aria-sort")
        elif tag == "tr" and "data-row" in attrs:
            self._table["rows"].append((int(attrs["data-row"]), []))
        elif tag == "td":
            self._cell = []

    def handle_data(self, data):
        if self._cell is not None:
            self._cell.append(data)

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            self._table["rows"][-1][1].append("".join(self._cell))
            self._cell = None
        elif tag == "table":
            self._table = None


def _tables(html):
    parser = _Tables()
    parser.feed(html)
    return parser.tables


def _dump_dom(browser, path, fragment, profile):
    proc = subprocess.run(
        [browser, "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
         f"--user-data-dir={profile}", "--dump-dom", f"{Path(path).as_uri()}#sort={fragment}"],
        capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "</html>" in proc.stdout, proc.stderr[-2000:]
    return proc.stdout


def _frames(root):
    """``{table id: the frame the page shows, in the page's row order}``."""
    table = read_long_table(root / "tables" / "matrix.csv")
    frames = {"summary": read_summary(root / "tables" / "summary.csv")}
    for problem in dict.fromkeys(table["problem"]):
        frames[f"runs-{problem}"] = main_runs(table, problem)[0]
    return frames


def test_page_is_one_self_contained_file(page):
    root, _ = page
    html = (root / "index.html").read_text()
    assert external_references(html) == []
    assert "<link" not in html and "<script src" not in html
    assert html.count('src="data:image/png;base64,') == len(PAGE_FIGURES)
    assert "image not available" not in html
    findings = (root / "findings.md").read_text()
    assert "## Across problems" in findings and ">Across problems</h4>" in html
    tables = _tables(html)
    assert set(tables) == {"summary", "runs-sphere", "runs-catenoid"}
    for name, frame in _frames(root).items():
        assert [r for r, _ in tables[name]["rows"]] == list(range(len(frame)))
    assert len(tables["runs-sphere"]["rows"]) == 4 and len(tables["runs-catenoid"]["rows"]) == 2


def test_rows_in_the_browser_follow_pandas_sort(browser, page, tmp_path):
    root, _ = page
    frames = _frames(root)
    checked, moved = 0, 0
    for fragment in FRAGMENTS:
        column, descending = fragment.lstrip("-"), fragment.startswith("-")
        tables = _tables(_dump_dom(browser, root / "index.html", fragment, tmp_path / "profile"))
        assert set(tables) == set(frames)
        for name, frame in frames.items():
            shown = tables[name]
            if column not in shown["columns"]:
                continue
            assert shown["sorted"][column] == ("descending" if descending else "ascending")
            expected = frame.sort_values(column, ascending=not descending, kind="stable",
                                         na_position="last").index.tolist()
            order = [r for r, _ in shown["rows"]]
            assert order == expected, (fragment, name, order, expected)
            # the rows really are those rows: the scheme cell of each matches the frame
            col = shown["columns"].index("scheme")
            assert [cells[col] for _, cells in shown["rows"]] == \
                frame.loc[expected, "scheme"].tolist()
            checked += 1
            moved += order != sorted(order)
    assert checked >= 2 * len(FRAGMENTS)
    assert moved >= 3  # not only tables that were already in order


MEASURE = """<script>window.addEventListener("load", function () {
  var d = document.documentElement, s = document.getElementById("summary").parentElement;
  var out = {page: [d.scrollWidth, d.clientWidth], summary: [s.scrollWidth, s.clientWidth],
    figures: Array.prototype.map.call(document.querySelectorAll("figure img"), function (i) {
      return [i.alt, i.clientWidth]; })};
  var p = document.createElement("pre"); p.id = "measured"; p.textContent = JSON.stringify(out);
  document.body.appendChild(p); });</script></body>"""


def _measure(browser, page_path, profile, width=1280):
    """Widths in CSS px of the page at a ``width`` px window: ``page`` and ``summary``
    (scroll width, client width: equal when nothing scrolls sideways), ``figures``
    (name, shown width). Measured in a copy of the page with a probe script."""
    import json
    import re

    probe = Path(page_path).with_name("probe.html")
    probe.write_text(Path(page_path).read_text().replace("</body>", MEASURE))
    proc = subprocess.run(
        [browser, "--headless", "--disable-gpu", "--no-sandbox", "--no-first-run",
         f"--user-data-dir={profile}", f"--window-size={width},900", "--dump-dom",
         probe.as_uri()], capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 0, proc.stderr[-2000:]
    found = re.search(r'<pre id="measured">(.*?)</pre>', proc.stdout)
    assert found, proc.stdout[-2000:]
    return json.loads(found.group(1).replace("&quot;", '"'))


def _longest_names(root, dest):
    """A copy of the matrix folder whose tables carry the registry's longest scheme and
    problem names and a long status (the widest summary the matrix can show)."""
    import pandas as pd

    from mcfbench.running.problems import PROBLEMS
    from mcfbench.running.schemes import SCHEMES

    shutil.copytree(root, dest)
    scheme = max(SCHEMES, key=len) + "@bdf3"
    problem = max(PROBLEMS, key=len)
    for name in ("summary.csv", "matrix.csv"):
        frame = pd.read_csv(dest / "tables" / name)
        frame["scheme"] = frame["scheme"].replace({"ddfv": scheme})
        frame["problem"] = frame["problem"].replace({"catenoid": problem})
        frame.loc[frame.index[-1], "status"] = "solver_stagnated"
        frame.to_csv(dest / "tables" / name, index=False)
    write_matrix_page(dest, dest / "index.html")
    return dest


def test_summary_fits_a_laptop_and_figures_show_at_print_size(browser, page, tmp_path):
    """At a 1280 px window: neither the page nor the summary table scrolls sideways
    (also with the registry's longest names), and every figure is shown at print size
    (96 px to the inch), so its text has the size it was drawn with, 8 pt at least
    (tests/mcfbench/studies/matrix/test_matrix.py checks the figures' fonts)."""
    from mcfbench.studies.matrix.page import print_width

    root, _ = page
    for folder in (root, _longest_names(root, tmp_path / "longest")):
        measured = _measure(browser, folder / "index.html", tmp_path / "profile")
        assert measured["page"][0] <= measured["page"][1], measured
        assert measured["summary"][0] <= measured["summary"][1], measured
        assert 1100 <= measured["summary"][1] <= 1280, measured
        shown = dict(measured["figures"])
        assert set(shown) == {name for name, _ in PAGE_FIGURES}
        for name, width in shown.items():
            assert abs(width - print_width(folder / "figures" / f"{name}.png")) <= 1, (name, width)
