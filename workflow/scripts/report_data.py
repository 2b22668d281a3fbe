"""The data of the reproduction report, read from the result files.

:func:`collect` reads everything the report shows into plain dicts and
lists (numbers stay numbers; ``None`` where a value is missing) and
evaluates the checks of ``paper/checks.yaml``; ``report_render.py`` turns
that into Markdown, HTML and LaTeX. Nothing here is a hand-typed result:
the published values come from ``paper/published/``, ours from

- ``results/tables/convergence.csv`` (+ ``.json``): Table 3.1 and the schemes,
- ``results/runs/{scheme}/level{k}.json``: run records (status, provenance),
- ``results/runs/figures/{figure}.json``, ``.npz``: the figures' runs,
- ``results/figures/*.png``, ``results/diagnostics/*.png``: the images,
- ``results/beyond/**``: the beyond-the-paper study, when present,
- ``ddfv/README.md``: the section "Deviations and interpretations".
"""

import json
import math
import os
import platform
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

PAPER_SCHEME = "ddfv"       # the scheme of the published Table 3.1
BASELINE = "cotan"          # the classical scheme it is compared with
SCHEME_NAMES = {"ddfv": "DDFV", "cotan": "cotangent"}
TABLE_COLUMNS = ("level", "nV", "nF", "nT", "tau", "N", "l2_error", "iterations", "eoc",
                 "cpu_seconds")
SIZE_COLUMNS = ("nV", "nF", "nT", "tau", "N")
DEVIATIONS_HEADING = "Deviations and interpretations"
SNAKEMAKE = "snakemake --cores 2"
MAX_TABLE_ROWS = 40         # longer CSV files of the beyond study are listed, not shown


class ReportError(ValueError):
    """An input the report cannot use; the message names the file."""


@dataclass
class Sources:
    """Where the report reads from (see the module docstring).

    ``out`` is the report's own folder: image paths in the Markdown are
    relative to it. ``beyond_targets`` are the files of ``snakemake beyond``
    (for the regeneration commands); ``figures`` the figure names to show
    (default: every experiment of :mod:`ddfv.experiments`).
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

def _finite(x):
    """``x`` as float, or None if missing or not finite."""
    try:
        value = float(x)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def _int(x):
    value = _finite(x)
    return None if value is None else int(round(value))


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
    import hashlib

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
    """Table 3.1 of ``paper/`` in the layout of :data:`ddfv.sphere.PUBLISHED`."""
    from ddfv.sphere import PUBLISHED_COLUMNS

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
    """The ``paper_*`` columns of convergence.csv (from ddfv.sphere.PUBLISHED)
    must equal paper/published/table_3_1.csv: the two copies may not drift."""
    rows = conv[conv["scheme"] == PAPER_SCHEME]
    for r in rows.itertuples():
        if r.level not in published.index:
            continue
        p = published.loc[r.level]
        for column in ("l2_error", "eoc", "iterations", "cpu_seconds"):
            ours, theirs = _finite(getattr(r, f"paper_{column}")), _finite(p[column])
            if ours != theirs:
                raise ReportError(
                    f"{path}: paper_{column} of level {r.level} is {ours}, but "
                    f"paper/published/table_3_1.csv has {theirs}: ddfv.sphere.PUBLISHED and "
                    "the published table have drifted apart (tests/test_report.py checks them)")


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
        paper = {c: (_finite(p[c]) if p is not None else None) for c in TABLE_COLUMNS}
        ours = {c: (_finite(o[c]) if o is not None else None) for c in TABLE_COLUMNS}
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
        row = {"level": int(level), "h": _finite(first["h"]), "tau": _finite(first["tau"]),
               "N": _int(first["N"]), "by_scheme": {}}
        for s in schemes:
            if s not in at.index:
                row["by_scheme"][s] = None
                continue
            r = at.loc[s]
            row["by_scheme"][s] = {"nV": _int(r["nV"]), "nF": _int(r["nF"]),
                                   "l2_error": _finite(r["l2_error"]), "eoc": _finite(r["eoc"]),
                                   "iterations": _int(r["iterations"]),
                                   "wall_seconds": _finite(r["wall_seconds"]),
                                   "status": str(r["status"])}
        a, b = row["by_scheme"].get(PAPER_SCHEME), row["by_scheme"].get(BASELINE)
        row["l2_baseline_over_paper"] = (b["l2_error"] / a["l2_error"]
                                         if a and b and a["l2_error"] and b["l2_error"]
                                         else None)
        row["wall_paper_over_baseline"] = (a["wall_seconds"] / b["wall_seconds"]
                                           if a and b and a["wall_seconds"]
                                           and b["wall_seconds"] else None)
        rows.append(row)
    return {"schemes": schemes, "names": {s: SCHEME_NAMES.get(s, s) for s in schemes},
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
                fa, fb = _finite(a), _finite(b)
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
    ddfv = [r for r in runs if r["scheme"] == PAPER_SCHEME and r["last_step"] is not None]
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
                "tau": run.tau, "steps": run.steps, "tangential": run.tangential,
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
            ddfv = [r for r in runs if r["scheme"] == PAPER_SCHEME]
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
    from importlib import metadata

    from ddfv.provenance import provenance

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


def _pct(x):
    return f"{100 * x:+.2f} %"


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
            f"paper's {r['paper']['l2_error']:.2e} ({_pct(r['l2_deviation'])}), outside the "
            f"{100 * r['l2_tolerance']:g} % tolerance.")
    if good:
        worst = max(good, key=lambda r: abs(r["l2_deviation"]))
        levels = ", ".join(str(r["level"]) for r in good)
        agrees.append(
            f"**L2 error (3.2)** within tolerance at level(s) {levels}; the largest "
            f"deviation is {_pct(worst['l2_deviation'])} at level {worst['level']} "
            f"(tolerance {100 * worst['l2_tolerance']:g} %).")
    for r in good:
        if r["l2_tolerance"] > float(checks["l2_relative"]["default"]):
            notes.append(
                f"**Level {r['level']}** is held to {100 * r['l2_tolerance']:g} % instead of "
                f"{100 * float(checks['l2_relative']['default']):g} %. "
                f"{checks['l2_relative'].get('why', '').strip()} Ours "
                f"{r['ours']['l2_error']:.4e}, paper {r['paper']['l2_error']:.2e} "
                f"({_pct(r['l2_deviation'])}).")
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
            if r["status"] not in (None, "ok"):
                (outside if r["scheme"] == PAPER_SCHEME else notes).append(
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
        from ddfv.experiments import EXPERIMENTS

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
    run_seconds = [_finite(r.get("wall_seconds")) for r in records.values() if r]
    fig_seconds = [_finite(f["seconds"]) for f in figs]
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
