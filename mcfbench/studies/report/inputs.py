"""The inputs of the reproduction report: the result files read and checked against the
paper (Table 3.1, the figures, the beyond study, the deviations, the provenance)."""

import hashlib
import json
import math
import os
import platform
import re
from dataclasses import dataclass, field
from importlib import metadata
from pathlib import Path

import pandas as pd
import yaml

from mcfbench.presentation.formats import (
    MISSING,
    finite_value,
)
from mcfbench.storage.provenance import provenance
from mcfbench.studies.convergence.tables import BASELINE, label, PAPER_SCHEME, PUBLISHED_COLUMNS

TABLE_COLUMNS = ("level", "nV", "nF", "nT", "tau", "N", "l2_error", "iterations", "eoc",
                 "cpu_seconds")


SIZE_COLUMNS = ("nV", "nF", "nT", "tau", "N")


DEVIATIONS_HEADING = "Deviations and interpretations"


SNAKEMAKE = "snakemake --cores 2"


MAX_TABLE_ROWS = 40         # longer CSV files of the beyond study are listed, not shown


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
    (default: every one of ``experiments``); ``experiments`` the figures'
    experiments (:data:`mcfbench.studies.figures.experiments.EXPERIMENTS`), passed in by
    the caller because presentation imports no study.
    """

    results: Path
    paper: Path
    readme: Path
    out: Path
    beyond: Path | None = None
    beyond_targets: tuple = ()
    figures: tuple | None = None
    experiments: dict = field(default_factory=dict, repr=False)

    def __post_init__(self):
        for name in ("results", "paper", "readme", "out"):
            setattr(self, name, Path(getattr(self, name)))
        if self.beyond is not None:
            self.beyond = Path(self.beyond)


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


def load_published(paper):
    """Table 3.1 as published (``paper/published/table_3_1.csv``), indexed by level."""
    path = Path(paper) / "published" / "table_3_1.csv"
    table = pd.read_csv(path)
    missing = [c for c in TABLE_COLUMNS if c not in table.columns]
    if missing:
        raise ReportError(f"{path}: missing column(s) {missing}")
    return table.set_index("level", drop=False)


def published_as_tuples(paper):
    """Table 3.1 of ``paper/`` in the layout of :data:`mcfbench.studies.convergence.tables.PUBLISHED`."""
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


def l2_tolerance(checks, level):
    levels = checks["l2_relative"].get("levels") or {}
    return float(levels.get(level, levels.get(str(level), checks["l2_relative"]["default"])))


def check_paper_columns(conv, published, path):
    """The ``paper_*`` columns of convergence.csv (from mcfbench.studies.convergence.tables.PUBLISHED)
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
                    f"paper/published/table_3_1.csv has {theirs}: mcfbench.studies.convergence.tables.PUBLISHED and "
                    "the published table have drifted apart (tests/mcfbench/studies/report/test_report.py checks them)")


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
    """``{(scheme, level): record or None}`` for every row of the table (the records of
    its provenance sidecar's ``inputs``, in the run store), and the disagreements
    between a record and its table row (a stale table)."""
    records, stale = {}, []
    sidecar = read_json(Path(results) / "tables" / "convergence.csv.json") or {}
    paths = {}                       # the table's records in the run store, by its sidecar
    for name in sidecar.get("inputs") or {}:
        path = Path(results).parent / name
        record = read_json(path)
        if record is not None:
            paths[record.get("scheme"), record.get("level")] = path
    for r in conv.itertuples():
        path = paths.get((r.scheme, int(r.level)))
        record = None if path is None else read_json(path)
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


def _csv_cell(x):
    """A value of a CSV table shown in the report: floats to 6 digits."""
    if isinstance(x, float):
        return MISSING if not math.isfinite(x) else f"{x:.6g}"
    return str(x)


def _csv_table(path, max_rows=None):
    """The first rows of a CSV file as text (``header``, ``rows``: the cells of a
    :class:`~mcfbench.presentation.tables.Table`, floats to 6 digits) and its size."""
    table = pd.read_csv(path)
    shown = table.head(max_rows or MAX_TABLE_ROWS)

    def cell(x):
        if isinstance(x, float):
            return MISSING if not math.isfinite(x) else f"{x:.6g}"
        return str(x)

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


def deviations(readme, heading=DEVIATIONS_HEADING, shift=1):
    """The section ``## heading`` of ``readme`` (up to the next ``## ``), its
    own heading left out and sub-headings shifted down by ``shift``."""
    text = Path(readme).read_text()
    match = re.search(rf"^##\s+{re.escape(heading)}\s*$(.*?)(?=^##\s|\Z)", text, re.M | re.S)
    if not match:
        raise ReportError(f"{readme}: no section '## {heading}'")
    body = match[1].strip("\n")
    return _HEADING.sub(lambda m: "#" * min(6, len(m[1]) + shift) + m[2], body) + "\n"


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
