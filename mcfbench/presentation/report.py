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
- ``results/runs/figures/{figure}.json``, ``.npz``: the figures' runs,
- ``results/figures/*.png``, ``results/diagnostics/*.png``: the images,
- ``results/beyond/**``: the beyond-the-paper study, when present,
- ``ddfv/README.md``: the section "Deviations and interpretations".

:func:`findings` writes the findings of the beyond study in words, every
number and verdict read from its tables. Scheme names in the text are the
registry's labels (:data:`mcfbench.running.schemes.SCHEMES`); numbers are formatted
and escaped by :mod:`mcfbench.presentation.formats`.

By hand, from the repository root: ``python -m mcfbench.presentation.report`` (results/
-> results/paper/).
"""

import argparse
import base64
import datetime
import functools
import hashlib
import json
import math
import mimetypes
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

import jinja2
import markdown
import numpy as np
import pandas as pd
import yaml

from mcfbench.presentation.convergence_tables import (
    BASELINE,
    PAPER_SCHEME,
    PUBLISHED_COLUMNS,
    label,
)
from mcfbench.presentation.formats import (
    MISSING,
    finite_value,
    fix,
    int_or,
    md_cell,
    num,
    pct,
    pct0,
    sci,
    sig,
    signed,
    tex_escape,
    tex_inline,
    tex_number,
    tex_tabular,
)
from mcfbench.running.schemes import get_scheme
from mcfbench.storage.atomic import write_files
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.provenance import provenance
from mcfbench.storage.statuses import STATE_STATUSES
from mcfbench.studies.figures import EXPERIMENTS

TABLE_COLUMNS = ("level", "nV", "nF", "nT", "tau", "N", "l2_error", "iterations", "eoc",
                 "cpu_seconds")
SIZE_COLUMNS = ("nV", "nF", "nT", "tau", "N")
DEVIATIONS_HEADING = "Deviations and interpretations"
SNAKEMAKE = "snakemake --cores 2"
MAX_TABLE_ROWS = 40         # longer CSV files of the beyond study are listed, not shown
MARKDOWN_EXTENSIONS = ["tables", "md_in_html", "attr_list", "fenced_code", "sane_lists", "toc"]


def _int(x):
    value = finite_value(x)
    return None if value is None else int(round(value))


class ReportError(ValueError):
    """An input the report cannot use; the message names the file."""


@dataclass
class Sources:
    """Where the report reads from (see the module docstring).

    ``out`` is the report's own folder: image paths in the Markdown are
    relative to it. ``beyond_targets`` are the files of ``snakemake beyond``
    (for the regeneration commands); ``figures`` the figure names to show
    (default: every experiment of :mod:`mcfbench.studies.figures`).
    """

    results: Path
    paper: Path
    readme: Path
    out: Path
    beyond: Path | None = None
    beyond_targets: tuple = ()
    figures: tuple | None = None
    experiments: dict | None = field(default=None, repr=False)

    def __post_init__(self):
        for name in ("results", "paper", "readme", "out"):
            setattr(self, name, Path(getattr(self, name)))
        if self.beyond is not None:
            self.beyond = Path(self.beyond)


# -- small readers --------------------------------------------------------------

def read_json(path):
    """The JSON object in ``path``, or None if the file does not exist."""
    path = Path(path)
    if not path.is_file():
        return None
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as err:
        raise ReportError(f"{path}: not valid JSON ({err})") from None


def read_yaml(path):
    try:
        return yaml.safe_load(Path(path).read_text())
    except OSError as err:
        raise ReportError(f"{path}: cannot read ({err})") from None


def rel(path, start):
    """``path`` relative to folder ``start`` with forward slashes."""
    return Path(os.path.relpath(Path(path).resolve(), Path(start).resolve())).as_posix()


def display_path(path, root):
    """``path`` as the repository names it (relative to the folder holding
    ``results/``), for regeneration commands and provenance."""
    try:
        return Path(path).resolve().relative_to(Path(root).resolve()).as_posix()
    except ValueError:
        return Path(path).as_posix()


def sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


# -- published values -------------------------------------------------------------

def load_published(paper):
    """Table 3.1 as published (``paper/published/table_3_1.csv``), indexed by level."""
    path = Path(paper) / "published" / "table_3_1.csv"
    table = pd.read_csv(path)
    missing = [c for c in TABLE_COLUMNS if c not in table.columns]
    if missing:
        raise ReportError(f"{path}: missing column(s) {missing}")
    return table.set_index("level", drop=False)


def published_as_tuples(paper):
    """Table 3.1 of ``paper/`` in the layout of :data:`mcfbench.presentation.convergence_tables.PUBLISHED`."""
    table = load_published(paper)
    out = {}
    for level, row in table.iterrows():
        values = []
        for column in PUBLISHED_COLUMNS:
            value = row[column]
            is_int = column in ("nV", "nF", "nT", "N", "iterations")
            values.append(int(value) if is_int else float(value))
        out[int(level)] = tuple(values)
    return out


# -- Table 3.1 ----------------------------------------------------------------------

def l2_tolerance(checks, level):
    levels = checks["l2_relative"].get("levels") or {}
    return float(levels.get(level, levels.get(str(level), checks["l2_relative"]["default"])))


def _check_paper_columns(conv, published, path):
    """The ``paper_*`` columns of convergence.csv (from mcfbench.presentation.convergence_tables.PUBLISHED)
    must equal paper/published/table_3_1.csv: the two copies may not drift."""
    rows = conv[conv["scheme"] == PAPER_SCHEME]
    for r in rows.itertuples():
        if r.level not in published.index:
            continue
        p = published.loc[r.level]
        for column in ("l2_error", "eoc", "iterations", "cpu_seconds"):
            ours, theirs = finite_value(getattr(r, f"paper_{column}")), finite_value(p[column])
            if ours != theirs:
                raise ReportError(
                    f"{path}: paper_{column} of level {r.level} is {ours}, but "
                    f"paper/published/table_3_1.csv has {theirs}: mcfbench.presentation.convergence_tables.PUBLISHED and "
                    "the published table have drifted apart (tests/harness/test_report.py checks them)")


def table_3_1(conv, published, checks):
    """One row per published level: the paper's values, ours, ratios, verdicts.

    Returns
    -------
    list of dict
        Keys: ``level``, ``ran`` (a row of ours exists), ``paper`` and
        ``ours`` (dicts of :data:`TABLE_COLUMNS`), ``sizes_match``,
        ``size_mismatch`` (columns that differ), ``l2_ratio``,
        ``l2_deviation`` (ratio - 1), ``l2_tolerance``, ``l2_ok``,
        ``eoc_difference``, ``eoc_tolerance``, ``eoc_ok`` (None when there is
        nothing to compare), ``iter_ratio``, ``iter_per_step`` (paper, ours),
        ``cpu_ratio``, ``status``, ``message``.
    """
    ours_rows = conv[conv["scheme"] == PAPER_SCHEME].set_index("level", drop=False)
    eoc_tol = float(checks["eoc_absolute"])
    rows = []
    for level in sorted(set(published.index) | set(ours_rows.index)):
        p = published.loc[level] if level in published.index else None
        o = ours_rows.loc[level] if level in ours_rows.index else None
        paper = {c: (finite_value(p[c]) if p is not None else None) for c in TABLE_COLUMNS}
        ours = {c: (finite_value(o[c]) if o is not None else None) for c in TABLE_COLUMNS}
        for d in (paper, ours):
            for c in ("level", "nV", "nF", "nT", "N", "iterations"):
                d[c] = _int(d[c])
        row = {"level": int(level), "ran": o is not None, "published": p is not None,
               "paper": paper, "ours": ours,
               "status": None if o is None else str(o["status"]),
               "message": "" if o is None or pd.isna(o["message"]) else str(o["message"])}
        if p is not None and o is not None:
            mismatch = [c for c in SIZE_COLUMNS
                        if not (paper[c] is not None and ours[c] is not None
                                and math.isclose(paper[c], ours[c], rel_tol=1e-12))]
            row["size_mismatch"] = mismatch
            row["sizes_match"] = not mismatch
        else:
            row["size_mismatch"], row["sizes_match"] = [], None
        tol = l2_tolerance(checks, level)
        ratio = (ours["l2_error"] / paper["l2_error"]
                 if None not in (ours["l2_error"], paper["l2_error"]) else None)
        row.update(l2_ratio=ratio, l2_deviation=None if ratio is None else ratio - 1.0,
                   l2_tolerance=tol,
                   l2_ok=None if ratio is None else abs(ratio - 1.0) <= tol)
        diff = (ours["eoc"] - paper["eoc"] if None not in (ours["eoc"], paper["eoc"])
                else None)
        row.update(eoc_difference=diff, eoc_tolerance=eoc_tol,
                   eoc_ok=None if diff is None else abs(diff) <= eoc_tol + 1e-12)

        def ratio_of(column):
            a, b = ours[column], paper[column]
            return a / b if a is not None and b not in (None, 0) else None

        row["iter_ratio"] = ratio_of("iterations")
        row["cpu_ratio"] = ratio_of("cpu_seconds")
        row["iter_per_step"] = {
            who: (d["iterations"] / d["N"] if d["iterations"] is not None and d["N"] else None)
            for who, d in (("paper", paper), ("ours", ours))}
        rows.append(row)
    return rows


def scheme_comparison(conv):
    """The schemes side by side per level (convergence.csv).

    Returns ``{"schemes": [...], "rows": [...], "has_baseline": bool}``; a
    row has ``level``, ``h``, ``tau``, ``N``, per scheme ``{nV, l2_error,
    eoc, iterations, wall_seconds, status}`` under ``by_scheme``, and
    ``l2_baseline_over_paper`` (cotangent L2 / DDFV L2) and
    ``wall_paper_over_baseline`` (DDFV wall / cotangent wall).
    """
    schemes = list(dict.fromkeys(conv["scheme"]))
    rows = []
    for level in sorted(conv["level"].unique()):
        at = conv[conv["level"] == level].set_index("scheme")
        first = at.iloc[0]
        row = {"level": int(level), "h": finite_value(first["h"]), "tau": finite_value(first["tau"]),
               "N": _int(first["N"]), "by_scheme": {}}
        for s in schemes:
            if s not in at.index:
                row["by_scheme"][s] = None
                continue
            r = at.loc[s]
            row["by_scheme"][s] = {"nV": _int(r["nV"]), "nF": _int(r["nF"]),
                                   "l2_error": finite_value(r["l2_error"]), "eoc": finite_value(r["eoc"]),
                                   "iterations": _int(r["iterations"]),
                                   "wall_seconds": finite_value(r["wall_seconds"]),
                                   "status": str(r["status"])}
        a, b = row["by_scheme"].get(PAPER_SCHEME), row["by_scheme"].get(BASELINE)
        row["l2_baseline_over_paper"] = (b["l2_error"] / a["l2_error"]
                                         if a and b and a["l2_error"] and b["l2_error"]
                                         else None)
        row["wall_paper_over_baseline"] = (a["wall_seconds"] / b["wall_seconds"]
                                           if a and b and a["wall_seconds"]
                                           and b["wall_seconds"] else None)
        rows.append(row)
    return {"schemes": schemes, "names": {s: label(s) for s in schemes},
            "paper": PAPER_SCHEME, "baseline": BASELINE,
            "rows": rows, "has_baseline": PAPER_SCHEME in schemes and BASELINE in schemes}


def run_records(results, conv):
    """``{(scheme, level): record or None}`` for every row of the table, and
    the disagreements between a record and its table row (a stale table)."""
    records, stale = {}, []
    for r in conv.itertuples():
        path = Path(results) / "runs" / r.scheme / f"level{r.level}.json"
        record = read_json(path)
        records[r.scheme, int(r.level)] = record
        if record is None:
            continue
        for key in ("l2_error", "iterations", "nV", "status"):
            a, b = record.get(key), getattr(r, key)
            if key == "status":
                same = str(a) == str(b)
            else:
                fa, fb = finite_value(a), finite_value(b)
                same = (fa is None and fb is None) or (
                    fa is not None and fb is not None and math.isclose(fa, fb, rel_tol=1e-9))
            if not same:
                stale.append({"path": display_path(path, Path(results).parent),
                              "key": key, "record": a, "table": b,
                              "scheme": r.scheme, "level": int(r.level)})
    return records, stale


# -- figures --------------------------------------------------------------------

def _npz_sizes(path):
    """``{run key: n_V}`` of a figure's frames (F- plus T-vertices)."""
    if not Path(path).is_file():
        return {}
    with np.load(path) as z:
        keys = {k.rsplit(".", 1)[0] for k in z.files}
        return {k: int(z[f"{k}.F"].shape[1]) + (int(z[f"{k}.T"].shape[1])
                                                 if f"{k}.T" in z.files else 0)
                for k in sorted(keys) if f"{k}.F" in z.files}


def _claim_verdict(check, runs, last_panel):
    """Evaluate a caption's ``check`` on the DDFV runs of a figure.

    Returns ``(ok or None, text)``.
    """
    ddfv = [r for r in runs if r["family"] == "ddfv" and r["last_step"] is not None]
    if not ddfv:
        return None, "no run record"
    firsts = [r["first_violation"] for r in ddfv]
    steps = max(r["last_step"] for r in ddfv)
    found = [f for f in firsts if f is not None]
    first = min(found) if found else None
    where = (f"first violation at n = {first}" if first is not None
             else f"no violation in {steps} steps")
    if check is None:
        return None, where
    if check == "none":
        ok = first is None and all(r["status"] == "ok" for r in ddfv)
        return ok, where
    if check == "after_last_panel":
        ok = first is not None and first > last_panel
        return ok, f"{where} (last panel n = {last_panel})"
    if check == "by_last_panel":
        ok = first is not None and first <= last_panel
        return ok, f"{where} (last panel n = {last_panel})"
    raise ReportError(f"captions.yaml: unknown check {check!r} "
                      "(none, after_last_panel, by_last_panel or null)")


def figures(sources, captions, experiments):
    """One dict per figure: images, captions (the paper's and ours), the
    runs of its record and the comparison of what the paper states."""
    results, out = sources.results, sources.out
    root = results.parent
    names = list(sources.figures) if sources.figures is not None else list(experiments)
    # each side-by-side comparison right after the paper's figure it extends
    order = {n: i for i, n in enumerate(names)}
    names.sort(key=lambda n: (order.get(n.replace("_cotan", ""), order[n]), n != n.replace(
        "_cotan", "")))
    items = []
    for name in names:
        experiment = experiments[name]
        png = results / "figures" / f"{name}.png"
        diag = results / "diagnostics" / f"{name}.png"
        record_path = results / "runs" / "figures" / f"{name}.json"
        record = read_json(record_path)
        sizes = _npz_sizes(results / "runs" / "figures" / f"{name}.npz")
        runs = []
        for run in experiment.runs:
            rec = (record or {}).get("runs", {}).get(run.key)
            runs.append({
                "key": run.key, "scheme": run.scheme, "label": run.label or run.key,
                "tau": run.tau, "steps": run.steps, "family": get_scheme(run.scheme).family,
                "scheme_label": label(run.scheme),
                "n_V": sizes.get(run.key),
                "status": rec["status"] if rec else None,
                "message": rec.get("message", "") if rec else "",
                "last_step": rec["last_step"] if rec else None,
                "first_violation": rec.get("first_violation") if rec else None,
                "violation": rec.get("violation", "") if rec else "",
                "iterations": rec.get("iterations") if rec else None,
                "wall_seconds": rec.get("wall_seconds") if rec else None,
            })
        panels = [s.step for s in experiment.shots]
        base = name.replace("_cotan", "")
        cap = captions.get(name) or {}
        item = {
            "name": name, "title": experiment.title, "caption": experiment.caption,
            "paper_figure": name in captions, "base": base,
            "number": cap.get("number") or (captions.get(base) or {}).get("number"),
            "paper_caption": cap.get("caption"), "claim": cap.get("claim"),
            "png": rel(png, out) if png.is_file() else None,
            "png_path": display_path(png, root),
            "diagnostics": rel(diag, out) if diag.is_file() else None,
            "record": display_path(record_path, root) if record else None,
            "status": record.get("status") if record else None,
            "seconds": (record or {}).get("seconds", {}).get("total"),
            "provenance": (record or {}).get("provenance"),
            "runs": runs, "panels": panels,
            "target": f"{SNAKEMAKE} {display_path(png, root)}",
            "rows": [],
        }
        if cap:
            ddfv = [r for r in runs if r["family"] == "ddfv"]
            ours_nv = [r["n_V"] for r in ddfv]
            ours_tau = sorted({r["tau"] for r in ddfv})
            rows = []
            if cap.get("n_V") is not None:
                rows.append({"what": "n_V", "paper": cap["n_V"], "ours": ours_nv,
                             "ok": list(cap["n_V"]) == ours_nv})
            else:
                rows.append({"what": "n_V", "paper": None, "ours": ours_nv, "ok": None})
            if cap.get("tau") is not None:
                rows.append({"what": "τ", "paper": [cap["tau"]], "ours": ours_tau,
                             "ok": ours_tau == [float(cap["tau"])]})
            elif any(r["steps"] for r in ddfv):
                rows.append({"what": "τ", "paper": None, "ours": ours_tau, "ok": None})
            if cap.get("steps") is not None:
                rows.append({"what": "time levels", "paper": cap["steps"], "ours": panels,
                             "ok": list(cap["steps"]) == panels})
            else:
                rows.append({"what": "time levels", "paper": None, "ours": panels,
                             "ok": None})
            if cap.get("claim"):
                ok, text = _claim_verdict(cap.get("check"), runs, max(panels))
                rows.append({"what": "behaviour", "paper": cap["claim"], "ours": text,
                             "ok": ok})
            item["rows"] = rows
        items.append(item)
    return items


# -- beyond the paper ------------------------------------------------------------

_IMG = re.compile(r"(!\[[^\]]*\]\()([^)\s]+)((?:\s+\"[^\"]*\")?\))")
_LINK = re.compile(r"(?<!!)(\[[^\]]*\]\()([^)\s#][^)\s]*)((?:\s+\"[^\"]*\")?\))")
_HEADING = re.compile(r"^(#{1,6})(\s)", re.M)


def rebase_markdown(text, source_dir, out_dir, shift=0):
    """Markdown of a file in ``source_dir`` made valid in ``out_dir``:
    relative image and link targets rewritten, headings shifted down by
    ``shift`` levels (fenced code left alone)."""
    def fix(match):
        target = match[2]
        if re.match(r"^[a-z]+:", target) or target.startswith("/"):
            return match[0]
        return match[1] + rel(Path(source_dir) / target, out_dir) + match[3]

    parts = re.split(r"(^```.*?^```)", text, flags=re.M | re.S)
    for i in range(0, len(parts), 2):
        part = _IMG.sub(fix, parts[i])
        part = _LINK.sub(fix, part)
        if shift:
            part = _HEADING.sub(lambda m: "#" * min(6, len(m[1]) + shift) + m[2], part)
        parts[i] = part
    return "".join(parts)


def _caption_of(path):
    """Caption of a beyond image: ``caption``/``title`` of a sibling JSON
    (``x.png.json`` or ``x.json``), else the file name in words."""
    for side in (path.with_name(path.name + ".json"), path.with_suffix(".json")):
        data = read_json(side) if side.is_file() else None
        if isinstance(data, dict):
            for key in ("caption", "title"):
                if isinstance(data.get(key), str):
                    return data[key]
    return path.stem.replace("_", " ").replace("-", " ").capitalize()


def _md_title(text, fallback):
    match = re.search(r"^#{1,6}\s+(.+)$", text, re.M)
    return match[1].strip() if match else fallback


def _strip_first_heading(text):
    return re.sub(r"\A\s*#{1,6}\s+.+\n", "", text, count=1)


def _csv_table(path, max_rows=None):
    table = pd.read_csv(path)
    shown = table.head(max_rows or MAX_TABLE_ROWS)

    def cell(x):
        if isinstance(x, float):
            return "–" if not math.isfinite(x) else f"{x:.6g}"
        return str(x).replace("|", "\\|")

    return {"header": [str(c) for c in shown.columns],
            "rows": [[cell(x) for x in r] for r in shown.itertuples(index=False)],
            "total": len(table), "shown": len(shown), "columns": len(table.columns)}


def _unfinished_runs(path):
    """Rows of a CSV with a ``status`` column whose status is not ``ok``, as
    short labels (scheme, level, study, t_f when the table has them)."""
    try:
        table = pd.read_csv(path)
    except (ValueError, OSError):
        return []
    if "status" not in table.columns:
        return []
    bad = table[table["status"].notna() & (table["status"].astype(str) != "ok")]
    labels = []
    for _, row in bad.iterrows():
        parts = [f"{key} {row[key]}" for key in ("study", "scheme", "level", "t_f")
                 if key in table.columns and pd.notna(row[key])]
        labels.append(", ".join(parts + [str(row["status"])]))
    return list(dict.fromkeys(labels))      # a time series repeats its run


def _provenance_of(data):
    """A provenance dict inside a JSON file's data, or None."""
    if not isinstance(data, dict):
        return None
    if isinstance(data.get("provenance"), dict):
        return data["provenance"]
    if "git_commit" in data and "packages" in data:
        return data
    return None


def beyond(sources):
    """What ``snakemake beyond`` left under ``results/beyond/``, if anything.

    ``findings.md`` first, then every other Markdown file, the CSV tables
    without a Markdown twin, and the PNG plots not already shown by a
    Markdown file. Logs are left out.
    """
    folder = sources.beyond
    result = {"present": False, "findings": None, "documents": [], "tables": [], "images": [],
              "data": [], "unfinished": [], "provenance": [], "folder": None,
              "target": f"{SNAKEMAKE} beyond"}
    if folder is None or not folder.is_dir():
        return result
    root, out = sources.results.parent, sources.out
    targets = {Path(t).as_posix() for t in sources.beyond_targets}
    files = sorted(p for p in folder.rglob("*")
                   if p.is_file() and "logs" not in p.relative_to(folder).parts
                   and not p.name.startswith("."))
    result["folder"] = display_path(folder, root)

    def target(path):
        shown = display_path(path, root)
        return f"{SNAKEMAKE} {shown}" if shown in targets else f"{SNAKEMAKE} beyond"

    referenced = set()
    for path in files:
        if path.suffix != ".md":
            continue
        text = path.read_text()
        for m in _IMG.finditer(text):
            referenced.add((path.parent / m[2]).resolve())
        tex = path.with_suffix(".tex")
        entry = {"path": display_path(path, root), "target": target(path),
                 "title": _md_title(text, path.stem.replace("_", " ")),
                 "text": rebase_markdown(_strip_first_heading(text), path.parent, out, shift=2),
                 "tex": display_path(tex, root) if tex.is_file() else None}
        if path.name == "findings.md" and result["findings"] is None:
            result["findings"] = entry
        else:
            result["documents"].append(entry)
    for path in files:
        if path.suffix == ".csv" and not path.with_suffix(".md").is_file():
            table = {"path": display_path(path, root), "target": target(path),
                     "title": path.stem.replace("_", " "), **_csv_table(path)}
            # long series are data, not tables to read: listed with their size
            (result["tables"] if table["total"] <= MAX_TABLE_ROWS else result["data"]).append(
                table)
        elif path.suffix == ".png" and path.resolve() not in referenced:
            result["images"].append({"path": display_path(path, root), "src": rel(path, out),
                                     "caption": _caption_of(path), "target": target(path)})
        if path.suffix == ".csv":
            unfinished = _unfinished_runs(path)
            if unfinished:
                result["unfinished"].append({"path": display_path(path, root),
                                             "runs": unfinished})
        if path.suffix == ".json":
            prov = _provenance_of(read_json(path))
            if prov:
                result["provenance"].append((display_path(path, root), prov))
    result["present"] = bool(result["findings"] or result["documents"] or result["tables"]
                             or result["images"] or result["data"])
    return result


# -- deviations ----------------------------------------------------------------------

def deviations(readme, heading=DEVIATIONS_HEADING, shift=1):
    """The section ``## heading`` of ``readme`` (up to the next ``## ``), its
    own heading left out and sub-headings shifted down by ``shift``."""
    text = Path(readme).read_text()
    match = re.search(rf"^##\s+{re.escape(heading)}\s*$(.*?)(?=^##\s|\Z)", text, re.M | re.S)
    if not match:
        raise ReportError(f"{readme}: no section '## {heading}'")
    body = match[1].strip("\n")
    return _HEADING.sub(lambda m: "#" * min(6, len(m[1]) + shift) + m[2], body) + "\n"


# -- provenance ------------------------------------------------------------------------

def _cpu_model():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or None


def provenance_summary(entries):
    """Summary of ``[(file, provenance dict)]``: what the result files were
    computed with (versions, commits, machines, dates), and every value on
    which the files disagree."""
    packages, commits, hosts, platforms, pythons, blas, created = {}, {}, {}, {}, {}, {}, []
    dirty = []
    for path, p in entries:
        if not isinstance(p, dict):
            continue
        for name, version in (p.get("packages") or {}).items():
            packages.setdefault(name, {}).setdefault(str(version), []).append(path)
        commits.setdefault(str(p.get("git_commit")), []).append(path)
        if p.get("git_dirty"):
            dirty.append(path)
        hosts.setdefault(str(p.get("host")), []).append(path)
        platforms.setdefault(str(p.get("platform")), []).append(path)
        pythons.setdefault(str(p.get("python")), []).append(path)
        threads = p.get("blas_threads") or {}
        blas.setdefault(", ".join(f"{k}={v}" for k, v in sorted(threads.items())) or "–",
                        []).append(path)
        if p.get("created"):
            created.append(p["created"])
    return {"files": len(entries), "packages": packages, "commits": commits, "dirty": dirty,
            "hosts": hosts, "platforms": platforms, "pythons": pythons, "blas": blas,
            "created_first": min(created) if created else None,
            "created_last": max(created) if created else None}


def build_environment():
    """Where and with what the report itself was built."""
    env = provenance()
    for name in ("jinja2", "markdown", "pyyaml"):
        try:
            env["packages"][name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            env["packages"][name] = None
    env["cpu"] = _cpu_model()
    env["cpus"] = os.cpu_count()
    return env


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
    if sources.experiments is None:
        sources.experiments = EXPERIMENTS
    published = load_published(paper)
    captions = read_yaml(paper / "published" / "captions.yaml")
    paper_settings = read_yaml(paper / "published" / "settings.yaml")
    checks = read_yaml(paper / "checks.yaml")
    conv_path = results / "tables" / "convergence.csv"
    if not conv_path.is_file():
        raise ReportError(f"{conv_path}: missing; build it with `{SNAKEMAKE} convergence`")
    conv = pd.read_csv(conv_path)
    _check_paper_columns(conv, published, conv_path)
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

def as_list(value):
    if value is None:
        return "not stated"
    if isinstance(value, (list, tuple)):
        return ", ".join(num(v) for v in value) if value else MISSING
    return md_cell(value)


def verdict(ok, text=""):
    """✓ / ✗ / ○ (compared, not checked) as a coloured span, with ``text``."""
    text = f" {text}" if text else ""
    if ok is None:
        return f'<span class="info">○</span>{text}'
    return (f'<span class="pass">✓{text}</span>' if ok
            else f'<span class="fail">✗{text}</span>')


FILTERS = {"sci": sci, "fix": fix, "sig": sig, "signed": signed, "pct": pct, "pct0": pct0,
           "num": num, "int_or": int_or, "listing": as_list, "verdict": verdict, "cell": md_cell}


@functools.lru_cache(maxsize=4)
def _environment(templates):
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(templates)),
                             undefined=jinja2.StrictUndefined, keep_trailing_newline=True,
                             autoescape=False)
    env.filters.update(FILTERS)
    return env


def environment(templates):
    """The Jinja2 environment of the template folder (compiled templates are
    kept between builds; a changed template file is reloaded)."""
    return _environment(str(Path(templates).resolve()))


# -- Markdown ---------------------------------------------------------------------------

def render_markdown(context, templates):
    """The report as Markdown (``reproduction.md.j2``), blank runs squeezed."""
    text = environment(templates).get_template("reproduction.md.j2").render(**context)
    text = re.sub(r"\n{3,}", "\n\n", text)
    return text.strip() + "\n"


# -- HTML -------------------------------------------------------------------------------

_IMG_SRC = re.compile(r'<img\b([^>]*?)\bsrc="([^"]*)"([^>]*)>')
_ANCHOR = re.compile(r'<a\b[^>]*?\bhref="([^"]*)"[^>]*>(.*?)</a>', re.S)


def data_uri(path):
    kind = mimetypes.guess_type(str(path))[0] or "application/octet-stream"
    return f"data:{kind};base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def embed_images(html, base):
    """Every ``<img src>`` relative to ``base`` replaced by a data URI; a
    missing or non-local image becomes a visible note."""
    def embed(match):
        src = match[2]
        if src.startswith("data:"):
            return match[0]
        path = Path(os.path.normpath(Path(base) / src))
        if re.match(r"^[a-z]+:", src) or not path.is_file():
            return f'<span class="fail">✗ image not available: <code>{src}</code></span>'
        return f'<img{match[1]}src="{data_uri(path)}"{match[3]}>'

    return _IMG_SRC.sub(embed, html)


def unlink_files(html):
    """Links other than in-page anchors become their text: the page is
    self-contained, and a relative link would break once it is moved."""
    def keep(match):
        href, text = match[1], match[2]
        return match[0] if href.startswith("#") else f'<span class="link">{text}</span>'

    return _ANCHOR.sub(keep, html)


def external_references(html):
    """Every ``src``/``href`` that is neither a data URI nor an in-page
    anchor (empty for a self-contained page)."""
    refs = re.findall(r'\b(?:src|href|srcset|poster|data)\s*=\s*"([^"]*)"', html)
    refs += re.findall(r"url\(\s*['\"]?([^'\")]+)", html)
    return [r for r in refs if not (r.startswith("data:") or r.startswith("#"))]


def render_html(markdown_text, base, templates, title):
    """The Markdown as one self-contained HTML page (images from ``base``)."""
    md = markdown.Markdown(extensions=MARKDOWN_EXTENSIONS,
                           extension_configs={"toc": {"toc_depth": "2-3"}})
    body = md.convert(markdown_text)
    body = unlink_files(embed_images(body, base))
    # wide tables scroll inside the page instead of widening it
    body = body.replace("<table>", '<div class="table-scroll"><table>').replace(
        "</table>", "</table></div>")
    toc = unlink_files(md.toc)
    # the TOC of the page without its wrapper div and without the title
    css = (Path(templates) / "style.css").read_text()
    env = environment(templates)
    return env.get_template("reproduction.html.j2").render(title=title, css=css, toc=toc,
                                                            body=body)


# -- LaTeX --------------------------------------------------------------------------------

_LIST_ITEM = re.compile(r"^(\s*)(?:(\d+)[.)]|[-*+])\s+(.*)$")


def markdown_to_tex(text):
    """A subset of Markdown as LaTeX: paragraphs, (nested) lists, headings
    (as \\paragraph), pipe tables, fenced code, inline markup."""
    lines = text.replace("\r\n", "\n").split("\n")
    out, i = [], 0
    while i < len(lines):
        line = lines[i]
        if not line.strip() or re.match(r"^\s*</?(div|figure|figcaption|details|summary)\b",
                                        line):
            i += 1
            continue
        if line.startswith("```"):
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            out.append("\\begin{verbatim}\n" + "\n".join(lines[i + 1:j]) + "\n\\end{verbatim}")
            i = j + 1
            continue
        heading = re.match(r"^#{1,6}\s+(.*)$", line)
        if heading:
            out.append(r"\paragraph{" + tex_inline(heading[1]) + "}")
            i += 1
            continue
        if line.lstrip().startswith("|"):
            j = i
            while j < len(lines) and lines[j].lstrip().startswith("|"):
                j += 1
            out.append(_tex_pipe_table(lines[i:j]))
            i = j
            continue
        if _LIST_ITEM.match(line):
            j = i
            block = []
            while j < len(lines) and (lines[j].strip() == "" or _LIST_ITEM.match(lines[j])
                                      or lines[j].startswith((" ", "\t"))):
                if lines[j].strip() == "" and (j + 1 >= len(lines) or not (
                        _LIST_ITEM.match(lines[j + 1]) or lines[j + 1].startswith((" ", "\t")))):
                    break
                block.append(lines[j])
                j += 1
            out.append(_tex_list(block))
            i = j
            continue
        j = i
        para = []
        while j < len(lines) and lines[j].strip() and not _LIST_ITEM.match(lines[j]) \
                and not lines[j].startswith(("#", "```", "|")):
            para.append(lines[j].strip())
            j += 1
        out.append(tex_inline(" ".join(para)))
        i = j
    return "\n\n".join(out) + "\n"


def _tex_list(block):
    """Items at the smallest indentation; deeper lines continue the item
    (text first, then nested lists or paragraphs, converted recursively)."""
    indent = min(len(_LIST_ITEM.match(b)[1]) for b in block if _LIST_ITEM.match(b))
    items, numbered = [], None
    for line in block:
        m = _LIST_ITEM.match(line)
        if m and len(m[1]) == indent:
            numbered = (m[2] is not None) if numbered is None else numbered
            items.append((m[3], []))
        elif items:
            items[-1][1].append(line)
    body = []
    for head, rest in items:
        rest = _dedent(rest)
        k = next((i for i, x in enumerate(rest) if _LIST_ITEM.match(x) or not x.strip()),
                 len(rest))
        text = " ".join([head] + [x.strip() for x in rest[:k]])
        tail = markdown_to_tex("\n".join(rest[k:])).strip() if k < len(rest) else ""
        body.append(r"\item " + tex_inline(text) + ("\n" + tail if tail else ""))
    env = "enumerate" if numbered else "itemize"
    return f"\\begin{{{env}}}\n" + "\n".join(body) + f"\n\\end{{{env}}}"


def _dedent(lines):
    indent = min((len(x) - len(x.lstrip()) for x in lines if x.strip()), default=0)
    return [x[indent:] for x in lines]


def _cells(line):
    line = line.strip()
    if line.startswith("|"):
        line = line[1:]
    if line.endswith("|") and not line.endswith("\\|"):
        line = line[:-1]
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)]


def _tex_pipe_table(lines):
    header = _cells(lines[0])
    rows = [_cells(x) for x in lines[2:]] if len(lines) > 1 else []
    return tex_tabular([tex_inline(h) for h in header],
                       [[tex_inline(c) for c in r] for r in rows])


def _tex_verdict(ok, text=""):
    mark = r"$\circ$" if ok is None else (r"\checkmark" if ok else r"$\times$")
    return f"{mark} {tex_escape(text)}".strip()


def latex_fragments(context, figure_prefix="figures/"):
    """``{name: text}`` of the LaTeX fragments (see the module docstring).

    Figure files are referenced as ``figures/<name>.pdf`` (and beyond
    images by their path under ``results/``): set ``\\graphicspath`` to the
    ``results/`` folder.
    """
    head = "% generated by mcfbench.presentation.report from the result files; do not edit\n"
    frags = {}
    env = context["environment"]
    frags["meta"] = head + "\n".join([
        rf"\newcommand{{\reportbuilt}}{{{tex_escape(context['built'])}}}",
        rf"\newcommand{{\reportcommit}}{{\texttt{{{tex_escape(env['git_commit'][:12])}}}}}",
        rf"\newcommand{{\reporthost}}{{\texttt{{{tex_escape(env['host'])}}}}}",
        rf"\newcommand{{\papertitle}}{{{tex_escape(context['paper_settings']['title'])}}}",
    ]) + "\n"
    frags["introduction"] = head + markdown_to_tex(context["text"]["introduction"])
    frags["scheme"] = head + markdown_to_tex(context["text"]["scheme"])

    # Table 3.1 check
    checks = context["checks"]
    header = ["level", "$n_V$", r"$\tau$", "$N$", "$L_2$ paper", "$L_2$ ours", "ours/paper",
              "tolerance", "EOC paper", "EOC ours", "difference",
              f"$\\le {checks['eoc_absolute']}$"]
    rows = []
    for r in context["table"]:
        rows.append([str(r["level"]), int_or(r["ours"]["nV"], r["paper"]["nV"]),
                     num(r["ours"]["tau"] if r["ran"] else r["paper"]["tau"]),
                     int_or(r["ours"]["N"], r["paper"]["N"]),
                     tex_number(sci(r["paper"]["l2_error"], 2)),
                     tex_number(sci(r["ours"]["l2_error"], 4)), fix(r["l2_ratio"], 4)
                     .replace(MISSING, "--"),
                     _tex_verdict(r["l2_ok"], pct0(r["l2_tolerance"])),
                     fix(r["paper"]["eoc"], 2).replace(MISSING, "--"),
                     fix(r["ours"]["eoc"], 3).replace(MISSING, "--"),
                     signed(r["eoc_difference"], 3).replace(MISSING, "--"),
                     _tex_verdict(r["eoc_ok"])])
    cost_header = ["level", "iter paper", "iter ours", "ours/paper", "CPU s paper", "CPU s ours",
                   "ours/paper"]
    cost = [[str(r["level"]), int_or(r["paper"]["iterations"]).replace(MISSING, "--"),
             int_or(r["ours"]["iterations"]).replace(MISSING, "--"),
             fix(r["iter_ratio"], 2).replace(MISSING, "--"),
             fix(r["paper"]["cpu_seconds"], 2).replace(MISSING, "--"),
             sig(r["ours"]["cpu_seconds"], 3).replace(MISSING, "--"),
             sig(r["cpu_ratio"], 3).replace(MISSING, "--")] for r in context["table"]]
    frags["table_3_1"] = head + "\n".join([
        r"\begin{table}[ht]",
        r"\caption{Table~3.1 of the paper against this reproduction (DDFV): $L_2$ error (3.2) "
        r"with the tolerance it is held to, and EOC (3.1). Checks: "
        r"\texttt{paper/checks.yaml}.}",
        r"\label{tab:reproduction-accuracy}",
        tex_tabular(header, rows, "r" * len(header)),
        r"\end{table}", "",
        r"\begin{table}[ht]",
        r"\caption{Cost: total BiCGStab iterations and CPU seconds, the paper's and ours "
        r"(compared, not checked).}",
        r"\label{tab:reproduction-cost}",
        tex_tabular(cost_header, cost, "r" * len(cost_header)),
        r"\end{table}",
    ]) + "\n"

    diff = context["differences"]
    parts = [head]
    for title, key, mark in (("Differences", "differs", r"$\neq$"),
                             ("Notes", "notes", r"$\circ$"),
                             ("Agreement", "agrees", r"\checkmark")):
        if diff[key]:
            parts.append(rf"\paragraph{{{title}.}}")
            parts.append("\\begin{itemize}\n" + "\n".join(
                rf"\item[{mark}] " + tex_inline(x) for x in diff[key]) + "\n\\end{itemize}")
    frags["differences"] = "\n".join(parts) + "\n"

    figs = [head]
    for f in context["figures"]:
        if f["png"] is None:
            continue
        label = (f"Fig.~{tex_escape(f['number'])}" if f["paper_figure"]
                 else f"Fig.~{tex_escape(f['number'])}, cotangent side by side")
        paper = (tex_inline(f["paper_caption"]) if f["paper_caption"]
                 else "Not in the paper.")
        checks_text = "; ".join(
            f"{tex_escape(row['what'])}: paper {tex_inline(as_list(row['paper']))}, ours "
            f"{tex_inline(as_list(row['ours']))} {_tex_verdict(row['ok'])}"
            for row in f["rows"])
        figs.append("\n".join([
            r"\begin{figure}[htbp]", r"\centering",
            rf"\includegraphics[width=\linewidth]{{{figure_prefix}{f['name']}.pdf}}",
            rf"\caption{{\textbf{{{label}: {tex_escape(f['title'])}.}} "
            rf"\emph{{Paper:}} {paper} \emph{{Ours:}} {tex_inline(f['caption'])}"
            + (rf" \emph{{Compared:}} {checks_text}." if checks_text else "") + "}",
            rf"\label{{fig:reproduction-{f['name'].replace('_', '-')}}}",
            r"\end{figure}", ""]))
    frags["figures"] = "\n".join(figs)

    beyond = context["beyond"]
    if beyond["present"]:
        parts = [head]
        if beyond["findings"]:
            parts.append(markdown_to_tex(beyond["findings"]["text"]))
        for d in beyond["documents"]:
            parts.append(rf"\subsection*{{{tex_inline(d['title'])}}}")
            # the Markdown the HTML shows, converted (the study's own LaTeX, when it
            # wrote one, is named for manuscripts: its escaping is not checked here)
            if d["tex"]:
                parts.append(f"% the study's own fragment: \\input{{{d['tex']}}}")
            parts.append(markdown_to_tex(d["text"]))
        for t in beyond["tables"]:
            parts.append(rf"\subsection*{{{tex_inline(t['title'])}}}")
            parts.append(tex_tabular([tex_inline(h) for h in t["header"]],
                                     [[tex_number(c) for c in row] for row in t["rows"]],
                                     "l" + "r" * (len(t["header"]) - 1)))
        for image in beyond["images"]:
            path = re.sub(r"^results/", "", image["path"])
            parts.append("\n".join([
                r"\begin{figure}[htbp]", r"\centering",
                rf"\includegraphics[width=0.8\linewidth]{{{tex_escape(path)}}}",
                rf"\caption{{{tex_inline(image['caption'])}}}", r"\end{figure}"]))
        frags["beyond"] = "\n\n".join(parts) + "\n"
    else:
        frags["beyond"] = head + tex_inline(
            f"Not run yet: `{beyond['target']}` computes the study beyond Table 3.1 and "
            "rebuilds this report.") + "\n"
    frags["deviations"] = head + markdown_to_tex(context["deviations"])

    prov = context["provenance"]
    rows = [["git commit(s)", ", ".join(rf"\texttt{{{tex_escape(c[:12])}}} ({len(v)})"
                                         for c, v in prov["commits"].items())],
            ["uncommitted changes", f"{len(prov['dirty'])} file(s)"],
            ["host(s)", ", ".join(tex_escape(h) for h in prov["hosts"])],
            ["platform", "; ".join(tex_escape(p) for p in prov["platforms"])],
            ["Python", ", ".join(tex_escape(p) for p in prov["pythons"])],
            ["created (UTC)", f"{tex_escape(prov['created_first'] or '--')} to "
                              f"{tex_escape(prov['created_last'] or '--')}"]]
    rows += [[tex_escape(name), ", ".join(tex_escape(v) for v in versions)]
             for name, versions in prov["packages"].items()]
    frags["provenance"] = head + "\n".join([
        r"\begin{table}[ht]",
        r"\caption{Provenance of the result files (from their JSON records).}",
        r"\label{tab:reproduction-provenance}",
        tex_tabular(["", "value"], rows, "ll"), r"\end{table}"]) + "\n"
    return frags

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
                  results / "runs" / "figures" / f"{name}.json",
                  results / "runs" / "figures" / f"{name}.npz"]
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



# -- PDF --------------------------------------------------------------------------------

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


# == the findings of the beyond study (rule beyond_findings) ============================

def _levels(values):
    values = sorted(int(v) for v in values)
    if not values:
        return ""
    if values == list(range(values[0], values[-1] + 1)) and len(values) > 2:
        return f"{values[0]}-{values[-1]}"
    return ", ".join(str(v) for v in values)


def _breakdown(r):
    text = (f"{r.status} at t = {r.t_failed:.4g} (step {round(r.t_failed / r.tau)} of {r.N})")
    if np.isfinite(r.t_monitor_end):
        text += f", T monitor {r.t_monitor_end:.3g} at the last time level computed"
    if np.isfinite(r.t_exit):
        text += f"; a T-vertex was outside its triangle from t = {r.t_exit:.4g} on"
    return text


def stability_section(levels, stability, schemes, t_final):
    """Which schemes finished every run, and where the others broke down."""
    lines, stable = ["## Which schemes stay stable", ""], []
    for scheme in schemes:
        runs = stability[stability["scheme"] == scheme]
        plain = levels[levels["scheme"] == scheme]
        has_t = len(runs) > 0
        if not has_t:
            runs = plain.assign(study="levels", t_final=t_final)
        failed = runs[runs["status"] != "ok"]
        finished = runs[runs["status"] == "ok"]
        outside = runs[np.isfinite(runs["t_exit"])] if has_t else runs.iloc[:0]
        head = f"- **{label(scheme)}** (`{scheme}`): "
        where = []
        for study, part in finished.groupby("study", sort=False):
            t = part["t_final"].iloc[0]
            where.append(f"level{'s' if len(part) > 1 else ''} {_levels(part['level'])} "
                         f"to t = {t:g}")
        if len(failed) == 0:
            if len(outside) == 0:
                stable.append(scheme)
            text = head + "every run finished (" + "; ".join(where) + ")"
            if has_t:
                text += (f"; the T monitor stayed at or above "
                         f"{runs['t_min_barycentric'].min():.3f}")
                text += (", no T-vertex left its triangle." if len(outside) == 0 else
                         f", but T-vertices left their triangles ({len(outside)} run(s)).")
            else:
                text += "; no T-vertices."
        else:
            parts = [f"level {r.level}" + (f" continued to t = {r.t_final:g}"
                                           if r.study == "long_time" else
                                           f" (t_f = {r.t_final:g})") + ": " + _breakdown(r)
                     for r in failed.itertuples()]
            text = head + f"broke down in {len(failed)} of {len(runs)} runs: " + \
                "; ".join(parts) + "."
            if where:
                text += " Finished: " + "; ".join(where)
                if has_t:
                    text += f" (smallest T monitor {finished['t_min_barycentric'].min():.3f})"
                text += "."
        lines.append(text)
    return lines + [""], stable


def accuracy_section(levels, paper_schemes):
    """L2 ours/paper and EOC on the levels of Table 3.1, per DDFV scheme."""
    lines = ["## Accuracy against the published Table 3.1", ""]
    for scheme in paper_schemes:
        rows = levels[(levels["scheme"] == scheme) & np.isfinite(levels["l2_ratio"])]
        if not len(rows):
            continue
        finest = rows.loc[rows["level"].idxmax()]
        eocs = rows[np.isfinite(rows["eoc"])]
        text = (f"- **{label(scheme)}**: L2 / published between {rows['l2_ratio'].min():.3f} and "
                f"{rows['l2_ratio'].max():.3f} on levels {_levels(rows['level'])}; on level "
                f"{finest.level} {sci(finest.l2_error, 4)} against {finest.paper_l2_error:.2e} "
                f"({pct(finest.l2_ratio - 1, 1)}).")
        if len(eocs):
            text += (" EOC " + ", ".join(f"{v:.2f}" for v in eocs["eoc"]) + " (published "
                     + ", ".join(f"{v:.2f}" for v in eocs["paper_eoc"]) + ").")
        lines.append(text)
    return lines + [""]


def finest_section(levels, schemes):
    """The finest level every scheme ran, beyond the paper, and the finer levels
    some schemes ran (``beyond.finest``): errors, orders and cost.

    Returns
    -------
    lines : list of str
    finest : int
        The finest level every scheme of ``schemes`` ran.
    """
    finest = int(levels.groupby("scheme")["level"].max()[schemes].min())
    deeper = levels[levels["level"] > finest]
    lines = [f"## Level {finest} (finest level run" +
             (f" by every scheme; level {_levels(deeper['level'].unique())} by "
              f"{', '.join(label(s) for s in dict.fromkeys(deeper['scheme']))} only)"
              if len(deeper) else ")"), ""]
    for scheme in schemes:
        rows = levels[(levels["scheme"] == scheme) & (levels["level"] >= finest)]
        for r in rows.itertuples():
            name = f"**{label(scheme)}**" + (f" on level {r.level}" if r.level > finest else "")
            cost = f"{r.wall_seconds:.0f} s wall, {r.peak_rss_mb:.0f} MB peak memory"
            if r.status == "ok":
                eoc = f", EOC {r.eoc:.3f} against level {r.level - 1}" \
                    if np.isfinite(r.eoc) else ""
                lines.append(f"- {name}: L2 {sci(r.l2_error, 4)}{eoc}; "
                             f"{r.iterations} BiCGStab iterations, {cost}.")
            else:
                lines.append(f"- {name}: no error, the run broke down: {_breakdown(r)} "
                             f"({cost} until then).")
    return lines + [""], finest


def cost_section(levels, schemes, reference, finest):
    """CPU time and iterations of each scheme against ``reference`` on the finest
    level where both finished, and on level ``finest`` (the finest every scheme ran)."""
    lines = ["## Cost", ""]
    ok = levels[levels["status"] == "ok"]
    cpu = ok.pivot(index="level", columns="scheme", values="cpu_seconds")
    iters = ok.pivot(index="level", columns="scheme", values="iterations")
    for scheme in schemes:
        if scheme == reference or scheme not in cpu or reference not in cpu:
            continue
        common = cpu[[scheme, reference]].dropna()
        if not len(common):
            continue
        level = int(common.index.max())
        lines.append(f"- **{label(scheme)}** on level {level}: {common.loc[level, scheme]:.3g} CPU s "
                     f"against {common.loc[level, reference]:.3g} s of {label(reference)} (ratio "
                     f"{common.loc[level, scheme] / common.loc[level, reference]:.2f}), "
                     f"{iters.loc[level, scheme]:.0f} BiCGStab iterations against "
                     f"{iters.loc[level, reference]:.0f}.")
    lines.append(f"- level {finest}: " + ", ".join(
        f"{label(r.scheme)} {r.cpu_seconds:.0f} CPU s"
        + ("" if r.status == "ok" else f" until it broke down at step "
           f"{round(r.t_failed / r.tau)} of {r.N}")
        for r in levels[levels["level"] == finest].itertuples()) + ".")
    lines.append("")
    lines.append("CPU seconds of the flow on one core, from the pipeline's run records "
                 "(wall seconds, in the tables, depend on the other jobs sharing the machine); "
                 "`benchmarks/bench_level6.py` times runs alone.")
    return lines + [""]


def order_section(levels, time, space, paper_schemes):
    lines = ["## Order in time and in space", ""]
    for scheme, part in time.groupby("scheme", sort=False):
        orders = part["order"].dropna()
        if part["status"].ne("ok").all() or not len(orders):
            lines.append(f"- time, **{label(scheme)}**: no order ({part['message'].iloc[0]}).")
            continue
        lines.append(f"- time (level {part['level'].iloc[0]}, tau {part['tau'].max():g} to "
                     f"{part['tau'].min():g}), **{label(scheme)}**: orders "
                     + ", ".join(f"{v:.2f}" for v in orders) + ".")
    if len(time) and time["status"].eq("ok").any():
        # an error e ~ C (tau - tau_ref) measured against the reference run gives
        # the order log((t1 - r) / (t2 - r)) / log(t1 / t2) > 1 for the last pair
        taus = np.sort(time.loc[time["status"] == "ok", "tau"].unique())[::-1]
        ref = time["reference_tau"].dropna().iloc[0]
        if len(taus) > 1:
            biased = np.log((taus[-2] - ref) / (taus[-1] - ref)) / np.log(taus[-2] / taus[-1])
            lines.append(f"  (Against a reference with tau = {ref:.3g} an exactly first-order "
                         f"error gives {biased:.2f} for the last pair: the reference's own "
                         "error, not a change of order.)")
    for scheme, part in space.groupby("scheme", sort=False):
        orders = part["eoc"].dropna()
        lines.append(f"- space (tau = {part['tau'].iloc[0]:.4g}, levels "
                     f"{_levels(part['level'])}), **{label(scheme)}**: EOC "
                     + (", ".join(f"{v:.2f}" for v in orders) if len(orders) else "none")
                     + ".")
    lines.append("")
    # the space error alone against the error of Table 3.1 (tau ~ h^2) on the same level
    both = space[space["status"] == "ok"].merge(
        levels[levels["status"] == "ok"], on=["scheme", "level"], suffixes=("_space", ""))
    both = both[both["scheme"].isin(paper_schemes)]
    if len(both):
        share = both["l2_error_space"] / both["l2_error"]
        mostly_time = share.max() < 0.5
        lines.append(f"With tau ~ h^2 the errors of Table 3.1 are "
                     f"{'mostly time error' if mostly_time else 'not dominated by either part'}"
                     f": on levels {_levels(both['level'].unique())} the error with tau = "
                     f"{space['tau'].iloc[0]:.4g} is {share.min():.2f}-{share.max():.2f} x "
                     "the error of the L2 table (DDFV schemes)"
                     + (", so their order 2 is mainly that of the first-order time error, "
                        "O(tau) = O(h^2)." if mostly_time else "."))
        lines.append("")
    finest = space[(space["level"] == space["level"].max()) & (space["status"] == "ok")]
    if len(finest) > 1:
        finest = finest.sort_values("l2_error")
        lines.append(f"In space alone (level {finest['level'].iloc[0]}, tau = "
                     f"{finest['tau'].iloc[0]:.4g}) the errors rank "
                     + " < ".join(f"{label(r.scheme)} {sci(r.l2_error)}"
                                  for r in finest.itertuples())
                     + ".")
    return lines + [""]


def summary(levels, stable, paper_schemes, finest):
    """The verdict in two sentences."""
    variants = [s for s in paper_schemes if s in stable]
    unstable = [s for s in paper_schemes if s not in stable]
    if not variants:
        return ["## Summary", "", "No DDFV scheme finished every run.", ""]
    rows = levels[(levels["level"] == finest) & levels["scheme"].isin(variants)]
    rows = rows[rows["status"] == "ok"].sort_values("l2_error")
    text = (f"Stable (every run finished, no T-vertex left its triangle): "
            f"{'; '.join(map(label, variants))}; not stable: "
            f"{'; '.join(map(label, unstable)) or 'none'}.")
    if len(rows):
        best = rows.iloc[0]
        text += f" On level {finest} the most accurate stable variant is {label(best.scheme)} " \
                f"(L2 {sci(best.l2_error, 4)}"
        others = [f"{label(r.scheme)} {r.l2_error / best.l2_error:.2f} x that" for r in
                  rows.iloc[1:].itertuples()]
        text += ("; " + ", ".join(others) if others else "") + ")."
    paper = levels[levels["scheme"].isin(variants) & np.isfinite(levels["l2_ratio"])]
    if len(paper):
        worst = paper.loc[(paper["l2_ratio"] - 1).abs().groupby(paper["scheme"]).idxmax()]
        text += " Largest deviation from the published errors (levels of Table 3.1): " + \
            "; ".join(f"{label(r.scheme)} {pct(r.l2_ratio - 1, 1)} (level {r.level})"
                      for r in worst.itertuples()) + "."
    return ["## Summary", "", text, ""]


def findings(levels, stability, time, space, schemes, paper_schemes, t_final, tau_1):
    """The findings of the beyond study (Markdown) from its tables (DataFrames of
    :func:`mcfbench.presentation.beyond_tables.beyond_tables`); ``schemes``: those of the level table,
    ``paper_schemes``: those compared with the published values."""
    parts = ["# Beyond Table 3.1: findings", "",
             "Generated by `mcfbench.presentation.report.findings` from the tables in "
             "`results/beyond/tables/` (every number below is read from them). Shrinking "
             f"unit sphere, t_f = {t_final:g} unless stated, tau = {tau_1:g} / 4^(level-1).",
             ""]
    stab, stable = stability_section(levels, stability, schemes, t_final)
    fine, finest = finest_section(levels, schemes)
    reference = paper_schemes[0] if paper_schemes else schemes[0]
    parts += summary(levels, stable, paper_schemes, finest)
    parts += stab + accuracy_section(levels, paper_schemes) + fine
    parts += cost_section(levels, schemes, reference, finest)
    parts += order_section(levels, time, space, paper_schemes)
    parts += ["## Figures and tables", "",
              "![L2 error per level](figures/levels.png)", "",
              "![T monitor against time](figures/t_monitor.png)", "",
              "![Convergence in time](figures/time_convergence.png)", "",
              "![Convergence in space](figures/space_convergence.png)", "",
              "Tables: [levels](tables/levels.md), [stability](tables/stability.md), "
              "[time](tables/time_convergence.md), [space](tables/space_convergence.md) "
              "(CSV and LaTeX next to them).", ""]
    return "\n".join(parts)


# -- by hand -----------------------------------------------------------------------------

def main(argv=None):
    """``python -m mcfbench.presentation.report``: the report from ``results/`` into ``results/paper/``."""
    parser = argparse.ArgumentParser(description="Build the reproduction report.")
    parser.add_argument("--results", type=Path, default=Path("results"))
    parser.add_argument("--paper", type=Path, default=Path("paper"))
    parser.add_argument("--readme", type=Path, default=Path("ddfv/README.md"))
    parser.add_argument("--out", type=Path, default=None,
                        help="report folder (default: RESULTS/paper)")
    parser.add_argument("--beyond", type=Path, default=None,
                        help="beyond-the-paper folder (default: RESULTS/beyond)")
    parser.add_argument("--log", type=Path, default=None)
    args = parser.parse_args(argv)
    sources = Sources(results=args.results, paper=args.paper, readme=args.readme,
                      out=args.out or args.results / "paper",
                      beyond=args.beyond or args.results / "beyond")
    log = setup_logging(args.log or sources.out / "report.log")
    try:
        build(sources, log=log)
    except ReportError as err:
        log.error("%s", err)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
