"""The reproduction report and the findings of the beyond study, from the result files.

:func:`build` reads everything the report shows (:func:`collect`: plain
dicts and lists, numbers stay numbers, ``None`` where a value is missing),
evaluates the checks of ``paper/checks.yaml`` and writes

- ``reproduction.md``: the report as Markdown (``paper/templates/
  reproduction.md.j2``, Jinja2; images linked relatively),
- ``reproduction.html``: the same as one self-contained page (CSS inline,
  images as base64 data URIs, links to files as plain text; opens offline),
- ``reproduction.json``: every check with its verdict, the provenance
  summary and the SHA-256 of every input,
- ``tex/*.tex``: LaTeX fragments (tables, figures, text) for
  ``paper/reproduction.tex`` or a manuscript (:func:`latex_fragments`;
  :func:`build_pdf` compiles the template with pdflatex).

Nothing here is a hand-typed result: the published values come from
``paper/published/``, ours from

- ``results/tables/convergence.csv`` (+ ``.json``): Table 3.1 and the schemes,
- ``results/runs/{scheme}/level{k}.json``: run records (status, provenance),
- ``results/runs/figures/{figure}.json`` and ``{figure}/<run>.npz``: the figures' runs,
- ``results/figures/*.png``, ``results/diagnostics/*.png``: the images,
- ``results/beyond/**``: the beyond-the-paper study, when present,
- ``ddfv/README.md``: the section "Deviations and interpretations".

The findings of the beyond study are worded by
:mod:`mcfbench.studies.beyond.findings` from its tables and the verdicts of
:func:`mcfbench.studies.beyond.findings`. Scheme names in the text are the
registry's labels (:data:`mcfbench.running.schemes.SCHEMES`); numbers are formatted
and escaped by :mod:`mcfbench.presentation.formats`.

By hand, from the repository root: ``mcfbench report`` (results/
-> results/paper/).
"""

import datetime
import json
import math
import re
import time
from pathlib import Path

import pandas as pd

from mcfbench.presentation.documents import (
    external_references,
    latex_fragments,
    render_html,
    render_markdown,
)
from mcfbench.presentation.formats import (
    finite_value,
    pct,
)
from mcfbench.storage.atomic import write_files
from mcfbench.storage.statuses import STATE_STATUSES
from mcfbench.studies.report.checks import figures
from mcfbench.studies.report.inputs import (
    SNAKEMAKE,
    ReportError,
    beyond,
    build_environment,
    check_paper_columns,
    deviations,
    display_path,
    load_published,
    provenance_summary,
    read_json,
    read_yaml,
    rel,
    run_records,
    scheme_comparison,
    sha256,
    table_3_1,
)

# -- small readers --------------------------------------------------------------


# -- published values -------------------------------------------------------------


# -- Table 3.1 ----------------------------------------------------------------------


# -- figures --------------------------------------------------------------------


# -- beyond the paper ------------------------------------------------------------


# -- deviations ----------------------------------------------------------------------


# -- provenance ------------------------------------------------------------------------


# -- the differences ---------------------------------------------------------------------

def _range(values):
    values = [v for v in values if v is not None]
    return (min(values), max(values)) if values else (None, None)


def deviation_number(text, keyword):
    """Number of the item of the deviations list whose bold title contains
    ``keyword`` (case-insensitive), or None."""
    for number, title in re.findall(r"^(\d+)\.\s+\*\*(.+?)\*\*", text, re.M):
        if keyword.lower() in title.lower():
            return int(number)
    return None


def differences(table, comparison, figs, stale, settings, paper_settings, checks, summary,
                records, beyond_data, deviations_text=""):
    """Every difference from the paper the data show, and what agrees.

    Returns ``{"outside": [...], "differs": [...], "notes": [...],
    "agrees": [...]}``, each a list of Markdown sentences built from the
    numbers (nothing hand-typed): ``outside`` what fails a check of
    ``paper/checks.yaml`` or is missing, ``differs`` what differs but is not
    checked (iterations, CPU time), ``notes`` what else one should know.
    """
    outside, differs, agrees, notes = [], [], [], []

    def deviation_ref(keyword):
        number = deviation_number(deviations_text, keyword)
        return f"deviation {number} below" if number else "see the deviations below"

    run = [r for r in table if r["ran"] and r["published"]]
    # -- Table 3.1: L2 error
    bad = [r for r in run if r["l2_ok"] is False]
    good = [r for r in run if r["l2_ok"]]
    for r in bad:
        outside.append(
            f"**L2 error, level {r['level']}:** {r['ours']['l2_error']:.4e} against the "
            f"paper's {r['paper']['l2_error']:.2e} ({pct(r['l2_deviation'])}), outside the "
            f"{100 * r['l2_tolerance']:g} % tolerance.")
    if good:
        worst = max(good, key=lambda r: abs(r["l2_deviation"]))
        levels = ", ".join(str(r["level"]) for r in good)
        agrees.append(
            f"**L2 error (3.2)** within tolerance at level(s) {levels}; the largest "
            f"deviation is {pct(worst['l2_deviation'])} at level {worst['level']} "
            f"(tolerance {100 * worst['l2_tolerance']:g} %).")
    for r in good:
        if r["l2_tolerance"] > float(checks["l2_relative"]["default"]):
            notes.append(
                f"**Level {r['level']}** is held to {100 * r['l2_tolerance']:g} % instead of "
                f"{100 * float(checks['l2_relative']['default']):g} %. "
                f"{checks['l2_relative'].get('why', '').strip()} Ours "
                f"{r['ours']['l2_error']:.4e}, paper {r['paper']['l2_error']:.2e} "
                f"({pct(r['l2_deviation'])}).")
    # -- EOC
    eoc = [r for r in run if r["eoc_ok"] is not None]
    for r in eoc:
        if not r["eoc_ok"]:
            outside.append(
                f"**EOC, level {r['level']}:** {r['ours']['eoc']:.3f} against "
                f"{r['paper']['eoc']:.2f} (difference {r['eoc_difference']:+.3f}, tolerance "
                f"{r['eoc_tolerance']:g}).")
    if eoc and all(r["eoc_ok"] for r in eoc):
        worst = max(eoc, key=lambda r: abs(r["eoc_difference"]))
        agrees.append(
            f"**EOC (3.1)** within {worst['eoc_tolerance']:g} of the paper's at every level; "
            f"largest difference {worst['eoc_difference']:+.3f} (level {worst['level']}).")
    # -- sizes
    for r in run:
        if r["size_mismatch"]:
            cols = ", ".join(f"{c} {r['ours'][c]:g} vs {r['paper'][c]:g}"
                             for c in r["size_mismatch"]
                             if r["ours"][c] is not None and r["paper"][c] is not None)
            outside.append(f"**Mesh or time step, level {r['level']}:** {cols}.")
    if run and all(r["sizes_match"] for r in run):
        agrees.append("**Meshes and time steps** (n_V, n_F, n_T, τ, N) equal the paper's at "
                      "every level run.")
    # -- not run / broken down
    missing = [r["level"] for r in table if r["published"] and not r["ran"]]
    if missing:
        outside.append(f"**Not run:** level(s) {', '.join(map(str, missing))} of Table 3.1 "
                       "are not in results/tables/convergence.csv (config `levels`).")
    for r in table:
        if r["ran"] and r["status"] != "ok":
            outside.append(f"**Level {r['level']} broke down** ({r['status']}): "
                           f"{r['message']}")
    # -- iterations and CPU time
    lo, hi = _range(r["iter_ratio"] for r in run)
    if lo is not None:
        per = [r for r in run if r["iter_per_step"]["ours"] and r["iter_per_step"]["paper"]]
        last = per[-1] if per else None
        text = (f"**BiCGStab iterations** differ: ours / paper between {lo:.2f} and {hi:.2f}")
        if last:
            text += (f"; at level {last['level']} {last['iter_per_step']['ours']:.2f} "
                     f"iterations per step against the paper's "
                     f"{last['iter_per_step']['paper']:.2f}")
        text += (". The paper states neither its stopping test nor its initial guess "
                 f"({deviation_ref('iteration')}: what we count and why); the counts are "
                 "reported, not checked.")
        differs.append(text)
    lo, hi = _range(r["cpu_ratio"] for r in run)
    if lo is not None:
        hosts = ", ".join(f"`{h}`" for h in summary["hosts"] if h != "None") or "unknown"
        cpu = f" ({summary['cpu']})" if summary.get("cpu") else ""
        differs.append(
            f"**CPU seconds** differ: ours / paper between {lo:.3g} and {hi:.3g} "
            f"(paper: {paper_settings.get('cpu', 'its machine')}; ours: host {hosts}{cpu}, "
            "one BLAS thread, other jobs sharing the machine). Times below about half a "
            "second are noise; they are reported, not checked.")
    # -- settings
    if settings:
        pairs = [("t_final", settings.get("t_final")), ("tau_level_1", settings.get("tau_level_1"))]
        for key, ours in pairs:
            theirs = paper_settings.get(key)
            if ours is None or theirs is None:
                continue
            if not math.isclose(float(ours), float(theirs), rel_tol=1e-12):
                outside.append(f"**Setting `{key}`:** ours {ours:g}, paper {theirs:g}.")
    # -- stale table
    for s in stale:
        outside.append(
            f"**Stale table:** `{s['path']}` has {s['key']} = {s['record']!r}, "
            f"`results/tables/convergence.csv` has {s['table']!r} "
            f"({s['scheme']}, level {s['level']}); rebuild with `{SNAKEMAKE} convergence`.")
    missing_records = [f"{s}/level{k}" for (s, k), rec in records.items() if rec is None]
    if missing_records:
        outside.append(f"**Missing run records:** {', '.join(missing_records)}.")
    # -- schemes
    if comparison["has_baseline"]:
        ratios = [r["l2_baseline_over_paper"] for r in comparison["rows"]]
        lo, hi = _range(ratios)
        if lo is not None:
            notes.append(
                f"**Cotangent scheme** on the same triangulations: its L2 error is "
                f"{lo:.3f} to {hi:.3f} times DDFV's (on n_F points instead of n_F + n_T).")
    # -- figures
    for f in figs:
        label = f"Figure {f['number']}" if f["paper_figure"] else f["title"]
        if f["png"] is None:
            outside.append(f"**{label}:** not built (`{f['target']}`).")
            continue
        for row in f["rows"]:
            if row["ok"] is False:
                outside.append(f"**{label}, {row['what']}:** paper {_list(row['paper'])}, "
                               f"ours {_list(row['ours'])}.")
        if f["paper_figure"] and f["rows"] and all(r["ok"] is not False for r in f["rows"]):
            checked = [r["what"] for r in f["rows"] if r["ok"]]
            if checked:
                agrees.append(f"**{label}:** {', '.join(checked)} as in the paper.")
        for r in f["runs"]:
            if r["status"] in (None, "ok"):
                continue
            if r["status"] in STATE_STATUSES and r["last_step"] == r["steps"]:
                # an invalid state recorded while the run went on (the figures show
                # what happens after it; the "behaviour" row compares it with the paper)
                notes.append(f"**{label}, {r['label']} run:** {r['status']} recorded at "
                             f"the first defect, the run went on to n = {r['steps']}: "
                             f"{r['message']}")
            else:
                (outside if r["family"] == "ddfv" else notes).append(
                    f"**{label}, {r['label']} run:** {r['status']}: {r['message']}")
    # -- provenance
    commits = [c for c in summary["commits"] if c not in ("None", "unknown")]
    if len(commits) > 1:
        notes.append(f"**Provenance:** the result files come from {len(commits)} different "
                     "commits (see [Environment and provenance](#environment-and-provenance)).")
    if summary["dirty"]:
        notes.append(f"**Provenance:** {len(summary['dirty'])} result file(s) were computed "
                     "from a working tree with uncommitted changes.")
    # -- time budget
    budget = checks.get("pipeline_seconds")
    spent = summary.get("job_seconds")
    if budget and spent is not None:
        sentence = (f"**Time:** the jobs of the default pipeline recorded {spent:.1f} s of "
                    f"computation (runs and figures, one core each; imports and Snakemake's "
                    f"overhead not included) against a budget of {budget:g} s wall time "
                    "for `snakemake --cores 2`.")
        (agrees if spent <= budget else outside).append(sentence)
    if not beyond_data["present"]:
        notes.append(f"**Beyond the paper:** not run yet (`{beyond_data['target']}`).")
    if beyond_data["unfinished"]:
        # the table that names most of them (the study's tables overlap)
        table = max(beyond_data["unfinished"], key=lambda t: len(t["runs"]))
        notes.append(
            f"**Beyond the paper:** {len(table['runs'])} run(s) of the beyond study did not "
            f"finish ({'; '.join(table['runs'])}; `{table['path']}`). See "
            "[Beyond the paper](#beyond-the-paper).")
    return {"outside": outside, "differs": differs, "notes": notes, "agrees": agrees}


def _list(value):
    if value is None:
        return "not stated"
    if isinstance(value, (list, tuple)):
        return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value)
    return str(value)


# -- everything --------------------------------------------------------------------------

def collect(sources):
    """Read every input and evaluate the checks: the report's context (a dict)."""
    results, paper = sources.results, sources.paper
    root = results.parent
    published = load_published(paper)
    captions = read_yaml(paper / "published" / "captions.yaml")
    paper_settings = read_yaml(paper / "published" / "settings.yaml")
    checks = read_yaml(paper / "checks.yaml")
    conv_path = results / "tables" / "convergence.csv"
    if not conv_path.is_file():
        raise ReportError(f"{conv_path}: missing; build it with `{SNAKEMAKE} convergence`")
    conv = pd.read_csv(conv_path)
    check_paper_columns(conv, published, conv_path)
    table_prov = read_json(results / "tables" / "convergence.csv.json") or {}
    settings = {k: v for k, v in (table_prov.get("config") or {}).items() if k != "rule"}

    rows = table_3_1(conv, published, checks)
    comparison = scheme_comparison(conv)
    records, stale = run_records(results, conv)
    figs = figures(sources, captions, sources.experiments)
    beyond_data = beyond(sources)

    entries = []
    if table_prov:
        entries.append((display_path(results / "tables" / "convergence.csv.json", root),
                        table_prov))
    for (scheme, level), rec in records.items():
        if rec and isinstance(rec.get("provenance"), dict):
            entries.append((f"results/runs/{scheme}/level{level}.json", rec["provenance"]))
    for f in figs:
        if f["provenance"]:
            entries.append((f["record"], f["provenance"]))
    entries += beyond_data["provenance"]
    summary = provenance_summary(entries)
    run_seconds = [finite_value(r.get("wall_seconds")) for r in records.values() if r]
    fig_seconds = [finite_value(f["seconds"]) for f in figs]
    summary["job_seconds"] = (sum(x for x in run_seconds + fig_seconds if x is not None)
                              if any(x is not None for x in run_seconds + fig_seconds)
                              else None)
    environment = build_environment()
    summary["cpu"] = environment.get("cpu")

    convergence_png = results / "figures" / "convergence.png"
    context = {
        "paper_settings": paper_settings, "checks": checks, "settings": settings,
        "table": rows, "comparison": comparison, "figures": figs, "beyond": beyond_data,
        "records": {f"{s}/level{k}": r is not None for (s, k), r in records.items()},
        "stale": stale,
        "convergence_png": rel(convergence_png, sources.out) if convergence_png.is_file()
        else None,
        "deviations": deviations(sources.readme),
        "deviations_source": display_path(sources.readme, root),
        "provenance": summary, "environment": environment,
        "table_provenance": {k: table_prov.get(k) for k in ("created", "git_commit",
                                                              "git_dirty", "host")},
    }
    context["differences"] = differences(rows, comparison, figs, stale, settings,
                                         paper_settings, checks, summary, records, beyond_data,
                                         context["deviations"])
    context["glance"] = glance(rows, figs, comparison)
    return context


def glance(rows, figs, comparison):
    """Counts for the summary box."""
    run = [r for r in rows if r["ran"] and r["published"]]
    l2 = [r["l2_ok"] for r in run if r["l2_ok"] is not None]
    eoc = [r["eoc_ok"] for r in run if r["eoc_ok"] is not None]
    sizes = [r["sizes_match"] for r in run if r["sizes_match"] is not None]
    paper_figs = [f for f in figs if f["paper_figure"]]
    stated = [row["ok"] for f in paper_figs for row in f["rows"]
              if row["ok"] is not None and row["what"] != "behaviour"]
    behaviour = [row["ok"] for f in paper_figs for row in f["rows"]
                 if row["ok"] is not None and row["what"] == "behaviour"]
    built = [f["png"] is not None for f in figs]
    return {
        "l2": (sum(l2), len(l2)), "eoc": (sum(eoc), len(eoc)), "sizes": (sum(sizes), len(sizes)),
        "stated": (sum(stated), len(stated)), "behaviour": (sum(behaviour), len(behaviour)),
        "built": (sum(built), len(built)),
        "iter_ratio": _range(r["iter_ratio"] for r in run),
        "cpu_ratio": _range(r["cpu_ratio"] for r in run),
        "levels": [r["level"] for r in run],
    }

# -- Jinja filters ------------------------------------------------------------------


# -- Markdown ---------------------------------------------------------------------------


# -- HTML -------------------------------------------------------------------------------


# -- LaTeX --------------------------------------------------------------------------------


# -- build ------------------------------------------------------------------------------

TEX_FRAGMENTS = ("meta", "introduction", "scheme", "table_3_1", "differences", "figures",
                 "beyond", "deviations", "provenance")
TEXTS = ("introduction", "scheme")
PACKAGE_NAMES = ("ddfv-mcf", "numpy", "scipy", "libigl", "pandas", "matplotlib", "snakemake",
                 "jinja2", "markdown", "pyyaml")
TITLE = "Reproduction report: DDFV for mean curvature flow of surfaces"


def default_outputs(out):
    out = Path(out)
    outputs = {"md": out / "reproduction.md", "html": out / "reproduction.html",
               "json": out / "reproduction.json"}
    outputs.update({f"tex_{name}": out / "tex" / f"{name}.tex" for name in TEX_FRAGMENTS})
    return outputs


def _inputs(sources, context):
    """Every file the report read, for the SHA-256 list of the JSON."""
    results, paper = sources.results, sources.paper
    paths = [results / "tables" / "convergence.csv", results / "tables" / "convergence.csv.json",
             results / "figures" / "convergence.png", sources.readme]
    paths += sorted((paper / "published").glob("*")) + [paper / "checks.yaml"]
    paths += sorted((paper / "text").glob("*.md")) + sorted((paper / "templates").glob("*"))
    paths += [results / "runs" / f"{key}.json" for key in context["records"]]
    for f in context["figures"]:
        name = f["name"]
        paths += [results / "figures" / f"{name}.png", results / "diagnostics" / f"{name}.png",
                  results / "runs" / "figures" / f"{name}.json"]
        paths += sorted((results / "runs" / "figures" / name).glob("*.npz"))
    if sources.beyond is not None and sources.beyond.is_dir():
        paths += sorted(p for p in sources.beyond.rglob("*") if p.is_file())
    root = results.parent
    return {display_path(p, root): sha256(p)
            for p in paths if Path(p).is_file()}


def _json_default(value):
    if isinstance(value, Path):
        return value.as_posix()
    if isinstance(value, (set, tuple)):
        return list(value)
    if hasattr(value, "item"):
        return value.item()
    return str(value)


def build(sources, outputs=None, log=None):
    """Collect, check and render; write every output. Returns the context."""
    start = time.perf_counter()
    outputs = {k: Path(v) for k, v in (outputs or default_outputs(sources.out)).items()}
    context = collect(sources)
    root = sources.results.parent
    html_path = display_path(outputs["html"], root)
    context.update(
        built=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        snakemake=SNAKEMAKE,
        text={name: (sources.paper / "text" / f"{name}.md").read_text().strip()
              for name in TEXTS},
        package_names=PACKAGE_NAMES,
        deviation_refs={key: (f"deviation {n} below" if n else "see the deviations below")
                        for key, n in (("iteration", deviation_number(
                            context["deviations"], "iteration")),)},
        paths={"html": html_path, "json": display_path(outputs["json"], root),
               "table": display_path(sources.results / "tables" / "convergence.csv", root),
               "table_provenance": display_path(
                   sources.results / "tables" / "convergence.csv.json", root),
               "tex_table": display_path(outputs["tex_table_3_1"], root),
               "example_record": next(
                   (f"results/runs/{key}.json" for key in context["records"]),
                   "results/runs/ddfv/level1.json")},
    )
    templates = sources.paper / "templates"
    md = render_markdown(context, templates)
    html = render_html(md, outputs["md"].parent, templates, TITLE)
    external = external_references(html)
    if external:
        raise ReportError(f"the HTML report would load {external[:5]}: "
                          "every resource must be embedded")
    fragments = latex_fragments(context)

    summary = {
        "built": context["built"],
        "seconds": round(time.perf_counter() - start, 3),
        "glance": context["glance"], "differences": context["differences"],
        "table_3_1": context["table"], "schemes": context["comparison"],
        "figures": [{k: v for k, v in f.items() if k != "provenance"}
                    for f in context["figures"]],
        "beyond": {k: v for k, v in context["beyond"].items() if k != "provenance"},
        "stale": context["stale"], "settings": context["settings"],
        "checks": context["checks"], "provenance": context["provenance"],
        "environment": context["environment"],
        "inputs": _inputs(sources, context),
        "outputs": {k: display_path(v, root) for k, v in outputs.items()},
    }
    write_files({outputs["md"]: md, outputs["html"]: html,
                 **{outputs[f"tex_{name}"]: fragments[name] for name in TEX_FRAGMENTS},
                 outputs["json"]: json.dumps(summary, indent=2, default=_json_default) + "\n"})
    if log:
        differs = context["differences"]["differs"]
        log.info("report: %d difference(s) from the paper, %d note(s); %.2f s",
                 len(differs), len(context["differences"]["notes"]),
                 time.perf_counter() - start)
        for item in differs:
            log.info("differs: %s", item)
        log.info("wrote %s", ", ".join(str(p) for p in outputs.values()))
    return context
