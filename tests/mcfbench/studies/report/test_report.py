"""The reproduction report (mcfbench/studies/report/page.py, workflow/scripts/report*.py, paper/).

Built from small synthetic result files in a temporary folder (the layout
of results/, three levels, three figures), with the real paper/ sources and
ddfv/README.md. Checked: every output is written; the HTML needs nothing
but itself and embeds every image; a changed table value or run record
changes the report, and values outside the tolerances are flagged; the
published Table 3.1 equals mcfbench.studies.convergence.tables.PUBLISHED exactly; the beyond study
is included when present; the deviations come from ddfv/README.md.
"""

import json
import math
import re
import shutil
import struct
import zlib
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from mcfbench.presentation import documents
from mcfbench.running.schemes import SCHEMES
from mcfbench.storage.frames import save_frames
from mcfbench.studies.convergence.tables import PUBLISHED
from mcfbench.studies.figures.experiments import EXPERIMENTS, PAPER_FIGURES
from mcfbench.studies.report import inputs as report_inputs
from mcfbench.studies.report import page as report

REPO = Path(__file__).resolve().parents[4]

LEVELS = (1, 2, 3)
FIGURES = ("fig_3_2", "fig_3_6", "fig_3_6_cotan", "fig_3_7")
PROVENANCE = {"created": "2026-01-02T03:04:05+00:00", "python": "3.11.7",
              "packages": {"ddfv-mcf": "0.1.0", "numpy": "2.4.6"},
              "git_commit": "0123456789abcdef0123456789abcdef01234567", "git_dirty": False,
              "host": "testhost", "platform": "Linux-test",
              "blas_threads": {"OMP_NUM_THREADS": "1"}, "config": {}, "config_hash": "x"}


def png(seed):
    """A valid 2 x 2 RGB PNG whose bytes depend on ``seed``."""
    raw = b"".join(b"\x00" + bytes([(seed * 37 + i * 11) % 256 for i in range(6)])
                   for _ in range(2))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 2, 2, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


def write_png(path, seed):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(png(seed))


def convergence_table():
    """convergence.csv of levels 1-3 near the published values."""
    rows = []
    for scheme, factor in (("ddfv", 1.002), ("cotan", 1.06)):
        for level in LEVELS:
            nV, nF, nT, tau, N, l2, it, eoc, cpu = PUBLISHED[level]
            paper = scheme == "ddfv"
            rows.append({
                "scheme": scheme, "label": SCHEMES[scheme].label, "level": level,
                "h": 0.6 / 2 ** (level - 1), "nV": nV if paper else nF, "nF": nF,
                "nT": nT if paper else 0, "tau": tau, "N": N, "l2_error": l2 * factor,
                "eoc": float("nan"), "iterations": it + 3, "cpu_seconds": cpu / 10,
                "wall_seconds": cpu / 9, "wall_time_ratio": float("nan"), "status": "ok",
                "t_failed": float("nan"), "t_min_barycentric": 0.33,
                "paper_l2_error": l2 if paper else float("nan"),
                "paper_eoc": eoc if paper else float("nan"),
                "paper_iterations": it if paper else float("nan"),
                "paper_cpu_seconds": cpu if paper else float("nan"),
                "l2_ratio": factor if paper else float("nan"), "message": ""})
    table = pd.DataFrame(rows)
    for scheme in ("ddfv", "cotan"):
        part = table["scheme"] == scheme
        l2 = table.loc[part, "l2_error"].to_numpy()
        table.loc[part, "eoc"] = np.r_[np.nan, np.log2(l2[:-1] / l2[1:])]
    return table


def record_of(row):
    return {"scheme": row["scheme"], "level": int(row["level"]), "nV": int(row["nV"]),
            "l2_error": float(row["l2_error"]), "iterations": int(row["iterations"]),
            "wall_seconds": float(row["wall_seconds"]), "status": row["status"],
            "provenance": dict(PROVENANCE)}


def figure_record(name):
    experiment = EXPERIMENTS[name]
    runs = {}
    for run in experiment.runs:
        unsupported = run.scheme == "cotan"
        violation = 592 if (run.scheme == "ddfv" and run.shape == "cylinder") else None
        runs[run.key] = {
            "run": run.config(),
            "status": "unsupported" if unsupported else "t_escaped" if violation else "ok",
            "message": "needs a closed surface" if unsupported else "",
            "failed_step": -1, "last_step": 0 if unsupported else run.steps,
            "frames": [0], "iterations": 10, "wall_seconds": 0.5,
            "first_violation": violation,
            "violation": f"step {violation}: T-vertex left its triangle" if violation else ""}
    return {"experiment": name, "title": experiment.title, "status": "ok", "runs": runs,
            "seconds": {"compute": 1.0, "draw": 1.0, "total": 2.5},
            "provenance": dict(PROVENANCE)}


def figure_frames(folder, name):
    """One frames file per run of the figure (mcfbench.storage.frames), one frame each."""
    for run in EXPERIMENTS[name].runs:
        sizes = {"bumpy_sphere": (642, 1280), "cylinder": (216, 384)}[run.shape]
        extra = SCHEMES[run.scheme].extra_points
        arrays = {"vertices": np.zeros((1, sizes[0], 3)),
                  "faces": np.zeros((0, 3), int), "steps": np.zeros(1, int), "t": np.zeros(1)}
        if extra:
            arrays["extra_points"] = np.zeros((1, sizes[1], 3))
        save_frames(folder / f"{run.key}.npz", arrays)


@pytest.fixture
def results(tmp_path):
    """A results/ folder of levels 1-3 and three figures (see the module docstring)."""
    root = tmp_path / "results"
    (root / "tables").mkdir(parents=True)
    table = convergence_table()
    table.to_csv(root / "tables" / "convergence.csv", index=False)
    config = {"rule": "convergence_table", "levels": list(LEVELS), "schemes": ["ddfv", "cotan"],
              "tau_level_1": 0.04, "t_final": 0.08, "rtol": 1e-9}
    inputs = {}
    for _, row in table.iterrows():      # in the run store, named by the table's sidecar
        path = root / "runs" / "sphere" / row["scheme"] / f"level{row['level']}" / \
            f"{row['level']:016x}.json"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(record_of(row)))
        inputs[path.relative_to(tmp_path).as_posix()] = {}
    (root / "tables" / "convergence.csv.json").write_text(
        json.dumps({**PROVENANCE, "config": config, "inputs": inputs}))
    write_png(root / "figures" / "convergence.png", 1)
    (root / "runs" / "figures").mkdir(parents=True)
    for i, name in enumerate(FIGURES):
        write_png(root / "figures" / f"{name}.png", 10 + i)
        write_png(root / "diagnostics" / f"{name}.png", 20 + i)
        (root / "runs" / "figures" / f"{name}.json").write_text(json.dumps(figure_record(name)))
        figure_frames(root / "runs" / "figures" / name, name)
    return root


def sources(results, **kw):
    return report_inputs.Sources(results=results, paper=REPO / "paper",
                               readme=REPO / "ddfv" / "README.md", out=results / "paper",
                               beyond=results / "beyond", figures=FIGURES,
                               experiments=EXPERIMENTS, **kw)


def build(results, **kw):
    """Build the report; return (context, markdown, html, checks JSON)."""
    context = report.build(sources(results, **kw))
    out = results / "paper"
    return (context, (out / "reproduction.md").read_text(),
            (out / "reproduction.html").read_text(),
            json.loads((out / "reproduction.json").read_text()))


def b64(path):
    return documents.data_uri(path).split(",", 1)[1]


class References(HTMLParser):
    """Every URL-carrying attribute and every element that loads something."""

    def __init__(self):
        super().__init__()
        self.urls, self.loaders = [], []

    def handle_starttag(self, tag, attrs):
        for name, value in attrs:
            if name in ("src", "href", "srcset", "poster", "data", "action") and value:
                self.urls.append((tag, name, value))
        if tag in ("link", "script", "iframe", "object", "embed"):
            self.loaders.append(tag)


# -- outputs -------------------------------------------------------------------

def test_every_output_is_written(results):
    build(results)
    out = results / "paper"
    for path in report.default_outputs(out).values():
        assert path.is_file() and path.stat().st_size > 0, path


def test_html_is_self_contained(results):
    _, _, html, _ = build(results)
    parser = References()
    parser.feed(html)
    assert not parser.loaders
    outside = [(tag, name, url) for tag, name, url in parser.urls
               if not (url.startswith("data:") or url.startswith("#"))]
    assert outside == []
    assert documents.external_references(html) == []
    assert "url(" not in html.split("<style>")[1].split("</style>")[0]


def test_html_embeds_every_figure_image(results):
    _, md, html, _ = build(results)
    images = [results / "figures" / "convergence.png"]
    images += [results / sub / f"{name}.png" for name in FIGURES
               for sub in ("figures", "diagnostics")]
    for path in images:
        assert b64(path) in html, path
        assert Path("..", path.relative_to(results)).as_posix() in md, path
    assert html.count("<img ") == len(images)


def test_in_page_links_point_to_headings(results):
    _, _, html, _ = build(results)
    ids = set(re.findall(r'\bid="([^"]+)"', html))
    anchors = set(re.findall(r'href="#([^"]+)"', html))
    assert anchors and anchors <= ids


def test_report_takes_a_few_seconds(results):
    _, _, _, checks = build(results)
    assert checks["seconds"] < 10


# -- numbers come from the result files -------------------------------------------

def test_scheme_names_come_from_the_registry(results):
    _, md, _, checks = build(results)
    assert checks["schemes"]["names"] == {s: SCHEMES[s].label for s in ("ddfv", "cotan")}
    assert f"{SCHEMES['cotan'].label} L2" in md


def test_table_values_and_ratios_come_from_the_table(results):
    context, md, _, checks = build(results)
    table = pd.read_csv(results / "tables" / "convergence.csv")
    ours = table[table["scheme"] == "ddfv"].set_index("level")
    for row in checks["table_3_1"]:
        level = row["level"]
        if level not in LEVELS:
            assert not row["ran"]
            continue
        assert row["ours"]["l2_error"] == ours.loc[level, "l2_error"]
        assert row["l2_ratio"] == pytest.approx(ours.loc[level, "l2_error"]
                                                / PUBLISHED[level][5], rel=1e-12)
        assert f"{ours.loc[level, 'l2_error']:.4e}" in md
    assert checks["glance"]["l2"] == [3, 3]


def test_changed_table_value_changes_the_report(results):
    _, md_before, html_before, _ = build(results)
    path = results / "tables" / "convergence.csv"
    table = pd.read_csv(path)
    at = (table["scheme"] == "ddfv") & (table["level"] == 2)
    table.loc[at, "l2_error"] *= 1.05                    # 5 % off the paper
    table.to_csv(path, index=False)
    _, md, html, checks = build(results)
    new = table.loc[at, "l2_error"].iloc[0]
    assert f"{new:.4e}" in md and f"{new:.4e}" not in md_before
    assert md != md_before and html != html_before
    row = next(r for r in checks["table_3_1"] if r["level"] == 2)
    assert row["l2_ok"] is False
    assert any("L2 error, level 2" in item for item in checks["differences"]["outside"])
    # the record still has the old value: the table is flagged as stale
    assert any("Stale table" in item for item in checks["differences"]["outside"])


def test_changed_run_record_changes_the_report(results):
    _, md_before, _, _ = build(results)
    path = results / "runs" / "sphere" / "ddfv" / "level3" / f"{3:016x}.json"
    record = json.loads(path.read_text())
    record["provenance"]["host"] = "otherhost"
    record["provenance"]["git_commit"] = "f" * 40
    path.write_text(json.dumps(record))
    _, md, _, checks = build(results)
    assert "otherhost" in md and "otherhost" not in md_before
    assert "ffffffffffff" in md
    assert any("2 different commits" in item for item in checks["differences"]["notes"])


def test_eoc_outside_tolerance_is_flagged(results):
    path = results / "tables" / "convergence.csv"
    table = pd.read_csv(path)
    at = (table["scheme"] == "ddfv") & (table["level"] == 3)
    table.loc[at, "eoc"] = 1.9
    table.to_csv(path, index=False)
    _, md, _, checks = build(results)
    row = next(r for r in checks["table_3_1"] if r["level"] == 3)
    assert row["eoc_ok"] is False
    assert any("EOC, level 3" in item for item in checks["differences"]["outside"])
    assert '<span class="fail">✗</span>' in md


def test_published_values_and_table_may_not_drift(results):
    path = results / "tables" / "convergence.csv"
    table = pd.read_csv(path)
    table.loc[table["scheme"] == "ddfv", "paper_l2_error"] *= 1.01
    table.to_csv(path, index=False)
    with pytest.raises(report_inputs.ReportError, match="drifted"):
        build(results)


def test_missing_figure_is_reported(results):
    (results / "figures" / "fig_3_2.png").unlink()
    _, md, html, checks = build(results)
    assert any("Figure 3.2" in item and "not built" in item
               for item in checks["differences"]["outside"])
    assert documents.external_references(html) == []


def test_figure_checks_compare_with_the_captions(results):
    _, md, _, checks = build(results)
    figs = {f["name"]: f for f in checks["figures"]}
    rows = {r["what"]: r for r in figs["fig_3_2"]["rows"]}
    assert rows["n_V"]["ours"] == [1922] and rows["n_V"]["ok"] is True
    assert rows["time levels"]["ok"] is True
    assert rows["behaviour"]["ok"] is True                  # no violation in the run
    rows = {r["what"]: r for r in figs["fig_3_6"]["rows"]}
    assert rows["behaviour"]["ok"] is True                  # violation at 592 <= 640
    assert "n = 592" in rows["behaviour"]["ours"]
    # a T-vertex escape recorded while the run went on is the figure's subject: a
    # note with its status, not a failure
    assert any("t_escaped recorded" in item for item in checks["differences"]["notes"])
    assert not any("t_escaped" in item for item in checks["differences"]["outside"])
    # a DDFV variant of the registry (ddfv-eliminate) is checked as DDFV
    rows = {r["what"]: r for r in figs["fig_3_7"]["rows"]}
    assert rows["n_V"]["ours"] == [600] and rows["behaviour"]["ok"] is True
    # the cotangent comparison follows the figure it extends
    assert [f["name"] for f in checks["figures"]] == ["fig_3_2", "fig_3_6", "fig_3_6_cotan",
                                                      "fig_3_7"]
    assert any("needs a closed surface" in item for item in checks["differences"]["notes"])


# -- published values -----------------------------------------------------------------

def _same(a, b):
    return a == b or (isinstance(a, float) and isinstance(b, float)
                      and math.isnan(a) and math.isnan(b))


def test_published_table_equals_mcfbench_tables_published():
    published = report_inputs.published_as_tuples(REPO / "paper")
    assert sorted(published) == sorted(PUBLISHED)
    for level, values in PUBLISHED.items():
        assert len(published[level]) == len(values)
        for ours, theirs in zip(published[level], values):
            assert type(ours) is type(theirs) and _same(ours, theirs), (level, ours, theirs)


def test_captions_cover_figures_3_1_to_3_8():
    captions = yaml.safe_load((REPO / "paper" / "published" / "captions.yaml").read_text())
    assert sorted(captions) == sorted(PAPER_FIGURES)
    for name, cap in captions.items():
        assert cap["number"] == name.removeprefix("fig_").replace("_", ".")
        assert cap["caption"] and len(cap["caption"]) < 200
        assert cap["check"] in (None, "none", "after_last_panel", "by_last_panel")
        assert cap["caption"] != EXPERIMENTS[name].caption


# -- beyond the paper ----------------------------------------------------------------

def test_beyond_is_included_when_present(results):
    _, md, _, checks = build(results)
    assert not checks["beyond"]["present"] and "Not run yet" in md
    beyond = results / "beyond"
    (beyond / "tables").mkdir(parents=True)
    (beyond / "findings.md").write_text(
        "# Findings\n\nLevel 6 converges at order 2.\n\n![levels](figures/levels.png)\n\n"
        "See [the table](tables/levels.md).\n")
    (beyond / "tables" / "levels.md").write_text(
        "# Levels 1-6\n\n| level | L2 |\n|---:|---:|\n| 6 | 1.2e-05 |\n")
    (beyond / "tables" / "levels.csv").write_text("level,L2\n6,1.2e-05\n")
    (beyond / "tables" / "small.csv").write_text("a,b\n1,2.5\n")
    (beyond / "tables" / "stability.csv").write_text(
        "study,scheme,level,status\nlevels,ddfv,6,solver_failed\nlevels,ddfv,5,ok\n")
    series = "scheme,level,n,status\n" + "".join(f"ddfv,6,{n},solver_failed\n"
                                                 for n in range(60))
    (beyond / "tables" / "t_monitor.csv").write_text(series)
    (beyond / "tables" / "levels.tex").write_text("\\begin{tabular}{rr}\\end{tabular}\n")
    write_png(beyond / "figures" / "levels.png", 30)
    write_png(beyond / "figures" / "t_monitor.png", 31)
    (beyond / "figures" / "t_monitor.png.json").write_text(json.dumps(
        {"caption": "Smallest barycentric coordinate over time"}))
    _, md, html, checks = build(
        results, beyond_targets=("results/beyond/findings.md",))
    assert checks["beyond"]["present"]
    assert "Level 6 converges at order 2." in md and "Levels 1-6" in md
    assert "../beyond/figures/levels.png" in md                   # rebased link
    assert "Smallest barycentric coordinate over time" in md
    assert "| 1 | 2.5 |" in md                                    # CSV without a twin
    assert md.count("| 6 | 1.2e-05 |") == 1                       # CSV with a twin: once
    for seed_file in ("levels.png", "t_monitor.png"):
        assert b64(beyond / "figures" / seed_file) in html
    assert documents.external_references(html) == []
    assert "snakemake --cores 2 results/beyond/findings.md" in md
    beyond_tex = (results / "paper" / "tex" / "beyond.tex").read_text()
    assert "% the study's own fragment: \\input{results/beyond/tables/levels.tex}" in beyond_tex
    assert "\\begin{tabular}" in beyond_tex and _balanced(beyond_tex)
    # runs that broke down are named once, a long series is listed, not shown
    notes = [n for n in checks["differences"]["notes"] if n.startswith("**Beyond the paper:**")]
    assert len(notes) == 1 and "study levels, scheme ddfv, level 6, solver_failed" in notes[0]
    assert "<code>results/beyond/tables/t_monitor.csv</code> | 60 | 4 |" in md


# -- deviations and LaTeX --------------------------------------------------------------

def test_deviations_are_read_from_ddfv_readme(results):
    _, md, _, _ = build(results)
    text = (REPO / "ddfv" / "README.md").read_text()
    section = text.split("## Deviations and interpretations", 1)[1].split("\n## ", 1)[0]
    items = re.findall(r"^\d+\. \*\*(.+?)\*\*", section, re.M)
    assert len(items) >= 5
    for item in items:
        assert f"**{item}**" in md
    assert "## Deviations and interpretations" in md


def _balanced(tex):
    depth = 0
    for i, ch in enumerate(tex):
        if ch in "{}" and (i == 0 or tex[i - 1] != "\\"):
            depth += 1 if ch == "{" else -1
            if depth < 0:
                return False
    return depth == 0


def test_latex_fragments_are_balanced(results):
    build(results)
    for path in sorted((results / "paper" / "tex").glob("*.tex")):
        tex = path.read_text()
        assert _balanced(tex), path.name
        for env in set(re.findall(r"\\begin\{(\w+)\}", tex)):
            assert tex.count(f"\\begin{{{env}}}") == tex.count(f"\\end{{{env}}}"), (path, env)
    table = (results / "paper" / "tex" / "table_3_1.tex").read_text()
    assert "\\toprule" in table and "1.34\\cdot 10^{-2}" in table


def test_markdown_to_tex_escapes_the_readme():
    tex = documents.markdown_to_tex(report_inputs.deviations(REPO / "ddfv" / "README.md"))
    assert _balanced(tex)
    assert "\\begin{enumerate}" in tex and "\\item \\textbf{" in tex
    prose = re.sub(r"\\texttt\{(?:[^{}]|\{[^{}]*\})*\}", "", tex)
    assert not re.search(r"(?<!\\)[_%#&]", prose.replace("\\_", "").replace("\\%", ""))


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="needs pdflatex")
def test_pdf_builds_when_tex_is_installed(results, tmp_path, monkeypatch):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    build(results)
    for name in (*FIGURES, "convergence"):
        fig = plt.figure(figsize=(2, 1))
        fig.savefig(results / "figures" / f"{name}.pdf")
        plt.close(fig)
    (results / "tables" / "convergence.tex").write_text("% empty\n")
    root = results.parent
    shutil.copytree(REPO / "paper", root / "paper")
    monkeypatch.chdir(root)
    pdf = documents.build_pdf(root / "results" / "paper" / "reproduction.pdf",
                               Path("paper/reproduction.tex"))
    assert pdf.read_bytes().startswith(b"%PDF")


def test_rule_declares_every_output_of_the_script():
    """workflow/rules/report.smk lists the LaTeX fragments mcfbench.studies.report.page writes."""
    rules = (REPO / "workflow" / "rules" / "report.smk").read_text()
    block = re.search(r"REPORT_TEX_FRAGMENTS = \[(.*?)\]", rules, re.S)[1]
    assert tuple(re.findall(r'"(\w+)"', block)) == report.TEX_FRAGMENTS
    for name in ("reproduction.md", "reproduction.html", "reproduction.json"):
        assert name in rules
