"""Tables of the study beyond Table 3.1 from its run records.

Called by rule ``beyond_tables`` (workflow/rules/beyond.smk). Every record
is checked first (:func:`run_records.read_record`, :func:`read_time_record`);
one bad record stops the aggregation with a message naming the file.

Writes, under ``results/beyond/tables/`` (each as CSV, Markdown and a
LaTeX fragment):

``levels``
    L2 error (3.2) and EOC (3.1) per scheme and level with ``tau ~ h^2``,
    next to the published Table 3.1 (for every DDFV variant), the status of
    every run and what the T monitor did;
``stability``
    one row per run with T-vertices (the levels and the long run): status,
    time of the breakdown, the T monitor at n = 0, its minimum, its value at
    the last time level reached and the first time it went below 0;
``time_convergence``, ``space_convergence``
    the orders in time (fixed mesh) and in space (fixed tiny tau);

and ``t_monitor.csv`` (the T monitor at every time level of the levels and
long-time runs, long format) and ``beyond.json`` (provenance).

Runs that broke down are rows like any other: ``status``, ``t_failed``, NaN
L2 error, and no EOC against them (:func:`convergence_table.eoc_column`).
"""

import hashlib
import sys
from pathlib import Path

import numpy as np
import pandas as pd
from run_records import (RECOMPUTE, RecordError, check_config_hash,  # first: sys.path
                         load_record, read_record, setup_logging, write_json_atomic,
                         write_text_atomic)

from convergence_table import (COLUMNS, _fix, _int, _md_table, _sci, _sig,  # noqa: E402
                               _tex_table, build_table, eoc_column, l2_cell, mesh_size)
from ddfv.provenance import provenance  # noqa: E402

FLOAT_FORMAT = None  # shortest round-trip repr, as convergence_table.py
MONITOR_COLUMNS = ["t_reached", "t_monitor_start", "t_monitor_end", "t_exit"]
LEVEL_COLUMNS = COLUMNS[:-1] + MONITOR_COLUMNS + ["message"]
STABILITY_COLUMNS = ["study", "scheme", "variant", "level", "nT", "tau", "t_final", "N",
                     "status", "t_failed", "t_reached", "t_monitor_start",
                     "t_min_barycentric", "t_monitor_end", "t_exit", "l2_error",
                     "iterations", "wall_seconds", "message"]
SPACE_COLUMNS = ["scheme", "variant", "level", "h", "nV", "nF", "nT", "tau", "t_final", "N",
                 "l2_error", "eoc", "iterations", "wall_seconds", "status", "t_failed",
                 "t_min_barycentric", "message"]
TIME_COLUMNS = ["scheme", "variant", "level", "t_final", "reference_tau", "tau", "N", "error",
                "order", "l2_error", "status", "message"]
TIME_FIELDS = ("study", "scheme", "module", "options", "variant", "level", "taus",
               "reference_factor", "reference_tau", "t_final", "rtol", "status", "message",
               "rows", "wall_seconds", "provenance")


# -- reading ------------------------------------------------------------------

def read_time_record(path, expected):
    """Read and check the record of one time study (beyond_time.py).

    Raises
    ------
    RecordError
        Unreadable, a missing key, or settings other than ``expected``.
    """
    record = load_record(path, TIME_FIELDS, "time record")
    if not isinstance(record["rows"], list):
        raise RecordError(f"{path}: key 'rows' should be a list; {RECOMPUTE}")
    check_config_hash(path, record, expected)
    return record


# -- the T monitor --------------------------------------------------------------

def monitor_summary(record):
    """What the T monitor of one run did.

    Returns
    -------
    dict
        ``t_reached`` (last time level computed), ``t_monitor_start`` (at
        n = 0), ``t_monitor_end`` (at ``t_reached``: for a run that broke
        down, the last value before the breakdown), ``t_exit`` (first time
        a T-vertex was outside its triangle, monitor < 0; NaN if never).
        NaN for schemes without T-vertices (empty series).
    """
    series = np.asarray(record["t_monitor"], dtype=float)
    tau = float(record["tau"])
    if len(series) == 0:
        reached = record["N"] * tau if record["status"] == "ok" else record["t_failed"] - tau
        return {"t_reached": reached, "t_monitor_start": np.nan, "t_monitor_end": np.nan,
                "t_exit": np.nan}
    outside = np.flatnonzero(series < 0)
    return {"t_reached": (len(series) - 1) * tau, "t_monitor_start": float(series[0]),
            "t_monitor_end": float(series[-1]),
            "t_exit": outside[0] * tau if len(outside) else np.nan}


def monitor_series(records, study):
    """The T monitor of every time level of ``records``, long format."""
    frames = []
    for r in records:
        series = np.asarray(r["t_monitor"], dtype=float)
        if len(series) == 0:
            continue
        n = np.arange(len(series))
        frames.append(pd.DataFrame({
            "study": study, "scheme": r["scheme"], "variant": r["variant"],
            "level": r["level"], "tau": r["tau"], "t_final": r["t_final"],
            "status": r["status"], "n": n, "t": n * r["tau"], "t_monitor": series}))
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(
        columns=["study", "scheme", "variant", "level", "tau", "t_final", "status", "n", "t",
                 "t_monitor"])


# -- the tables ---------------------------------------------------------------

def levels_table(records, schemes, levels, paper_schemes):
    """:func:`convergence_table.build_table` for every variant, with the T monitor.

    ``records`` maps ``(scheme, level)`` to run records.
    """
    table = build_table(records, schemes, levels, paper_schemes=set(paper_schemes))
    summary = pd.DataFrame([monitor_summary(records[s, lv]) for s, lv in
                            zip(table["scheme"], table["level"])])
    table = pd.concat([table, summary], axis=1)
    return table[LEVEL_COLUMNS]


def stability_table(level_records, long_records):
    """One row per run with T-vertices: the levels study, then the long runs."""
    rows = []
    for study, records in (("levels", level_records), ("long_time", long_records)):
        for r in records:
            if r["nT"] == 0:
                continue
            rows.append({"study": study, **{k: r[k] for k in STABILITY_COLUMNS
                                            if k in r}, **monitor_summary(r)})
    return pd.DataFrame(rows, columns=STABILITY_COLUMNS)


def space_table(records, schemes, levels):
    """Order in space: one row per (scheme, level), EOC between finished runs."""
    h = {level: mesh_size(level) for level in levels}
    parts = []
    for scheme in schemes:
        part = pd.DataFrame([records[scheme, level] for level in levels])
        part["h"] = part["level"].map(h)
        part["eoc"] = eoc_column(part["level"], part["l2_error"], part["status"])
        parts.append(part)
    return pd.concat(parts, ignore_index=True)[SPACE_COLUMNS]


def time_order(taus, errors, status):
    """Order ``log(e_{j-1} / e_j) / log(tau_{j-1} / tau_j)`` between finished runs.

    (3.1) with tau for h; NaN for the first row and next to a run that broke
    down. For halved time steps it is ``ddfv.convergence.time_convergence``'s
    ``eoc``.
    """
    taus = np.asarray(taus, dtype=float)
    ok = (np.asarray(status) == "ok") & np.isfinite(np.asarray(errors, dtype=float))
    e = np.where(ok, np.asarray(errors, dtype=float), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        order = np.r_[np.nan, np.log(e[:-1] / e[1:]) / np.log(taus[:-1] / taus[1:])]
    return np.where(np.r_[False, ok[1:] & ok[:-1]], order, np.nan)


def time_table(records):
    """Order in time: one row per (scheme, tau); a failed reference is one row."""
    parts = []
    for r in records:
        base = {"scheme": r["scheme"], "variant": r["variant"], "level": r["level"],
                "t_final": r["t_final"], "reference_tau": r["reference_tau"]}
        if r["status"] != "ok":
            parts.append(pd.DataFrame([{**base, "tau": np.nan, "N": np.nan, "error": np.nan,
                                        "order": np.nan, "l2_error": np.nan,
                                        "status": r["status"], "message": r["message"]}]))
            continue
        rows = pd.DataFrame(r["rows"])
        for column in ("tau", "error", "l2_error"):
            rows[column] = pd.to_numeric(rows[column], errors="coerce").astype(float)
        part = rows.assign(**base, message="")
        part["order"] = time_order(part["tau"], part["error"], part["status"])
        parts.append(part)
    table = pd.concat(parts, ignore_index=True)
    table["N"] = table["N"].astype("Int64")
    return table[TIME_COLUMNS]


# -- Markdown and LaTeX -------------------------------------------------------

def _failed(status):
    return status != "ok"


def levels_rows(table, schemes, paper_schemes):
    """L2 and EOC per level, the schemes side by side, the paper first."""
    header = ["level", "h", "tau", "N", "L2 paper", "EOC paper"]
    for s in schemes:
        header += [f"{s} L2", f"{s} EOC"] + ([f"{s}/paper"] if s in paper_schemes else [])
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = by.loc[(schemes[0], level)]
        paper = table[(table["level"] == level) & table["paper_l2_error"].notna()]
        row = [str(level), f"{first.h:.4f}", f"{first.tau:g}", str(first.N),
               _sci(paper["paper_l2_error"].iloc[0], 2) if len(paper) else "–",
               _fix(paper["paper_eoc"].iloc[0], 2) if len(paper) else "–"]
        for s in schemes:
            r = by.loc[(s, level)]
            row += [l2_cell(r, 4), _fix(r.eoc, 3)]
            if s in paper_schemes:
                row.append(_fix(r.l2_ratio, 3))
        rows.append(row)
    return header, rows


def cost_rows(table, schemes):
    """Iterations, CPU and wall seconds per level and scheme."""
    header = ["level", "N"]
    for s in schemes:
        header += [f"{s} iter", f"{s} CPU s", f"{s} wall s"]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        row = [str(level), str(by.loc[(schemes[0], level)].N)]
        for s in schemes:
            r = by.loc[(s, level)]
            row += [str(r.iterations), _sig(r.cpu_seconds, 3), _sig(r.wall_seconds, 3)]
        rows.append(row)
    return header, rows


def failure_lines(table):
    """One sentence per run that broke down (table with monitor columns)."""
    lines = []
    for r in table[table["status"] != "ok"].itertuples():
        study = f" ({r.study})" if "study" in table.columns else ""
        text = (f"{r.scheme} level {r.level}{study}: {r.status} at t = {r.t_failed:.4g} "
                f"(step {round(r.t_failed / r.tau)} of {r.N})")
        if np.isfinite(r.t_monitor_end):
            text += f"; T monitor {r.t_monitor_end:.3g} at t = {r.t_reached:.4g}"
            if np.isfinite(r.t_exit):
                text += f", below 0 (a T-vertex outside its triangle) from t = {r.t_exit:.4g}"
        lines.append(text + f". {r.message}")
    return lines


def stability_rows(table):
    header = ["study", "scheme", "level", "t_f", "N", "status", "t_failed",
              "T monitor n=0", "min T monitor", "T monitor at end", "T outside from t",
              "L2", "wall s"]
    rows = []
    for r in table.itertuples():
        rows.append([r.study, r.scheme, str(r.level), f"{r.t_final:g}", str(r.N), r.status,
                     _sig(r.t_failed, 4), _fix(r.t_monitor_start, 3),
                     _sig(r.t_min_barycentric, 3), _sig(r.t_monitor_end, 3),
                     _sig(r.t_exit, 4), _sci(r.l2_error, 4), _sig(r.wall_seconds, 3)])
    return header, rows


def time_rows(table):
    header = ["scheme", "tau", "N", "error at t_f", "order", "L2 (3.2)", "status"]
    rows = [[r.scheme, _sig(r.tau, 4), _int(r.N), _sci(r.error, 3), _fix(r.order, 3),
             _sci(r.l2_error, 3), r.status] for r in table.itertuples()]
    return header, rows


def space_rows(table, schemes):
    header = ["level", "h", "N"]
    for s in schemes:
        header += [f"{s} n_V", f"{s} L2", f"{s} EOC"]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = by.loc[(schemes[0], level)]
        row = [str(level), f"{first.h:.4f}", str(first.N)]
        for s in schemes:
            r = by.loc[(s, level)]
            row += [str(r.nV), l2_cell(r, 4), _fix(r.eoc, 3)]
        rows.append(row)
    return header, rows


def describe_levels(beyond, settings):
    return (f"Shrinking unit sphere (Section 3.1), t_f = {settings['t_final']:g}, "
            f"tau = {settings['tau_level_1']:g} / 4^(level-1) (tau ~ h^2), BiCGStab rtol = "
            f"{settings['rtol']:g}. L2: space-time error (3.2) (cotan: over vertices, "
            "lumped-mass weights); EOC (3.1) against the next coarser level, only between "
            "runs that finished; /paper: ours over the published L2 of Table 3.1 (levels "
            "1-5). A run that broke down shows `failed (t = time of the breakdown)`.")


def describe_time(beyond):
    study = beyond["time_study"]
    return (f"Icosphere level {study['level']} (fixed mesh), t_f = {study['t_final']:g}, "
            f"tau = {', '.join(f'{t:g}' for t in study['taus'])}. error: distance at t_f to "
            f"a reference with tau = {study['taus'][-1] / study['reference_factor']:g} "
            "on the same mesh, sqrt(sum_i chi_i |X_i - X_i^ref|^2 / 2) over F- and "
            "T-vertices (ddfv.convergence.time_convergence); order: log(e_prev / e) / "
            "log(tau_prev / tau); L2 (3.2): against the exact sphere (space + time error).")


def describe_space(beyond):
    study = beyond["space_study"]
    return (f"tau = {study['tau']:g} on every level, t_f = {study['t_final']:g}: the "
            "error (3.2) against the exact sphere with the time error made small; EOC "
            "(3.1) between consecutive levels.")


def describe_stability(beyond):
    long = beyond["long_time"]
    return ("T monitor: smallest barycentric coordinate of any T-vertex projected into "
            "its triangle (1/3 at the barycentre; below 0 a T-vertex is outside). "
            "`levels`: the runs of the L2 table (t_f as there); `long_time`: level "
            f"{long['level']} continued to t_f = {long['t_final']:g}. 'T monitor at end': "
            "at the last time level computed (for a run that broke down, the last one "
            "before the breakdown); 'T outside from t': first time the monitor was < 0.")


def markdown(title, description, tables, notes=()):
    parts = [f"# {title}", "", description, ""]
    for heading, (header, rows) in tables:
        if heading:
            parts += [f"## {heading}", ""]
        parts += [_md_table(header, rows), ""]
    if notes:
        parts += ["## Runs that did not finish", ""] + [f"- {n}" for n in notes] + [""]
    return "\n".join(parts)


_TEX_ESCAPES = {"\\": r"\textbackslash{}", "_": r"\_", "^": r"\^{}", "~": r"$\sim$",
                "%": r"\%", "&": r"\&", "#": r"\#", "|": r"$|$", "<": r"$<$",
                ">": r"$>$", "`": ""}


def tex_text(text):
    """Plain text as LaTeX (special characters escaped)."""
    return "".join(_TEX_ESCAPES.get(c, c) for c in text)


def tex_header(text):
    """A column header for :func:`convergence_table._tex_table` (which maps
    ``L2``, ``tau``, ``N``, ... to math): ``t_f`` as math, other ``_`` escaped."""
    return " ".join("$t_f$" if word == "t_f" else word.replace("_", r"\_")
                    for word in text.split(" "))


def latex(description, tables, notes=()):
    parts = ["% generated by workflow/scripts/beyond_tables.py; needs booktabs, graphicx"]
    for caption, label, (header, rows) in tables:
        parts += [_tex_table([tex_header(h) for h in header], rows,
                             caption=tex_text(f"{caption} {description}"), label=label), ""]
    if notes:
        parts += ["% runs that did not finish:"] + [f"% {n}" for n in notes]
    return "\n".join(parts) + "\n"


def documents(tables, beyond, settings, schemes, paper_schemes):
    """``name -> {"csv": text, "md": text, "tex": text}``."""
    levels, stability = tables["levels"], tables["stability"]
    time, space = tables["time_convergence"], tables["space_convergence"]
    time_schemes = list(dict.fromkeys(time["scheme"]))
    space_schemes = list(dict.fromkeys(space["scheme"]))
    level_notes = failure_lines(levels)
    stability_notes = failure_lines(stability)
    space_notes = [f"{r.scheme} level {r.level}: {r.status} at t = {r.t_failed:.4g}. "
                   f"{r.message}" for r in space[space["status"] != "ok"].itertuples()]
    time_notes = [f"{r.scheme}: {r.status}. {r.message}"
                  for r in time[time["status"] != "ok"].itertuples()]
    desc = {"levels": describe_levels(beyond, settings), "stability": describe_stability(beyond),
            "time_convergence": describe_time(beyond), "space_convergence": describe_space(beyond)}
    md = {
        "levels": markdown("Beyond Table 3.1: L2 error and EOC per level and variant",
                           desc["levels"],
                           [("L2 error and EOC", levels_rows(levels, schemes, paper_schemes)),
                            ("Cost: BiCGStab iterations, CPU and wall seconds of the flow "
                             "(one core; wall seconds depend on the other jobs running)",
                             cost_rows(levels, schemes))], level_notes),
        "stability": markdown("T-vertex stability: the T monitor of every run",
                              desc["stability"], [("", stability_rows(stability))],
                              stability_notes),
        "time_convergence": markdown("Convergence in time (fixed mesh)", desc["time_convergence"],
                                     [("", time_rows(time))], time_notes),
        "space_convergence": markdown("Convergence in space (fixed time step)",
                                      desc["space_convergence"],
                                      [("", space_rows(space, space_schemes))], space_notes),
    }
    tex = {
        "levels": latex(desc["levels"], [
            ("L2 error and EOC of the DDFV variants and the cotangent scheme.",
             "tab:beyond-levels", levels_rows(levels, schemes, paper_schemes)),
            ("Cost: BiCGStab iterations, CPU and wall seconds (one core).", "tab:beyond-cost",
             cost_rows(levels, schemes))], level_notes),
        "stability": latex(desc["stability"], [("T-vertex stability.", "tab:beyond-stability",
                                                stability_rows(stability))], stability_notes),
        "time_convergence": latex(desc["time_convergence"], [
            (f"Convergence in time ({', '.join(time_schemes)}).", "tab:beyond-time",
             time_rows(time))], time_notes),
        "space_convergence": latex(desc["space_convergence"], [
            ("Convergence in space.", "tab:beyond-space", space_rows(space, space_schemes))],
            space_notes),
    }
    return {name: {"csv": table.to_csv(index=False, float_format=FLOAT_FORMAT,
                                       lineterminator="\n"),
                   "md": md[name], "tex": tex[name]} for name, table in tables.items()}


# -- the job ------------------------------------------------------------------

def read_all(paths, expected):
    """``(records by path, errors by path)``; time records by their own reader."""
    records, errors = {}, {}
    for path in paths:
        try:
            if expected[path].get("study") == "time":
                records[path] = read_time_record(path, expected[path])
            else:
                records[path] = read_record(path, expected[path])
        except RecordError as err:
            errors[path] = str(err)
    return records, errors


def build_tables(inputs, records, beyond, paper_schemes):
    """All tables from the checked records; ``inputs`` maps a study to its paths."""
    level_records = {(records[p]["scheme"], records[p]["level"]): records[p]
                     for p in inputs["levels"]}
    long_records = [records[p] for p in inputs["long_time"]]
    space_records = {(records[p]["scheme"], records[p]["level"]): records[p]
                     for p in inputs["space"]}
    tables = {
        "levels": levels_table(level_records, beyond["schemes"], beyond["levels"],
                               paper_schemes),
        "stability": stability_table([level_records[s, lv] for s in beyond["schemes"]
                                      for lv in beyond["levels"]], long_records),
        "time_convergence": time_table([records[p] for p in inputs["time"]]),
        "space_convergence": space_table(space_records, beyond["space_study"]["schemes"],
                                         beyond["space_study"]["levels"]),
    }
    series = pd.concat([
        monitor_series([level_records[s, lv] for s in beyond["schemes"]
                        for lv in beyond["levels"]], "levels"),
        monitor_series(long_records, "long_time")], ignore_index=True)
    return tables, series


def main(inputs, expected, beyond, paper_schemes, settings, outputs, log_file):
    log = setup_logging(log_file)
    paths = [p for study in ("levels", "long_time", "space", "time") for p in inputs[study]]
    records, errors = read_all(paths, expected)
    if errors:
        for error in errors.values():
            log.error("invalid run record: %s", error)
        log.error("aggregation stopped: %d invalid run record(s)", len(errors))
        sys.exit(1)
    tables, series = build_tables(inputs, records, beyond, paper_schemes)
    texts = documents(tables, beyond, settings, beyond["schemes"], paper_schemes)
    written = {}
    for name, docs in texts.items():
        for ext, text in docs.items():
            write_text_atomic(outputs[f"{name}_{ext}"], text)
            written[outputs[f"{name}_{ext}"]] = text
    text = series.to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n")
    write_text_atomic(outputs["t_monitor"], text)
    written[outputs["t_monitor"]] = text
    sidecar = provenance({"rule": "beyond_tables", "beyond": beyond, **settings})
    sidecar["inputs"] = {
        path: {key: rec["provenance"].get(key) for key in
               ("config_hash", "git_commit", "git_dirty", "host", "created", "blas_threads")}
        for path, rec in records.items()}
    sidecar["outputs"] = {path: hashlib.sha256(t.encode()).hexdigest()
                          for path, t in written.items()}
    write_json_atomic(outputs["provenance"], sidecar)
    log.info("wrote %d files under %s", len(written) + 1, Path(outputs["provenance"]).parent)
    print(texts["levels"]["md"], file=sys.stderr)
    print(texts["stability"]["md"], file=sys.stderr)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main({study: [str(p) for p in getattr(sm.input, study)]
          for study in ("levels", "long_time", "space", "time")},
         dict(sm.params.expected), dict(sm.params.beyond), list(sm.params.paper_schemes),
         dict(sm.params.settings), {key: str(path) for key, path in sm.output.items()},
         sm.log[0])
