"""The tables of the benchmark matrix: the long table (one row per run and metric, EOC (3.1) of every error), the table of one problem, the summary (problem x scheme) and its cells (written by :mod:`mcfbench.presentation.tables`).

Errors and EOC
--------------
A metric is an *error* when its exact value is zero (:func:`is_error`:
``l2_error``, the catenoid's neck and profile errors, the height of the
hemisphere above the flat disk, the displacement of the flat patch). Its
EOC between levels ``k - 1`` and ``k`` is ``log2(|e_{k-1}| / |e_k|)``
(levels one apart, both runs finished), not computed (``eoc_below_accuracy``)
when either error is within the stated accuracy of the problem's reference
(``reference_accuracy``, a reference computed by schemes: the real meshes',
:func:`mcfbench.studies.matrix.reference_accuracies`): there the error says
nothing of the scheme's order. Other metrics (volume, area) have no exact
value: no EOC. The *main metric* of a problem
(:func:`main_metric`) is the one of the summary, the plots and the
findings.
"""


import numpy as np

from mcfbench.geometry.exact import eoc
from mcfbench.presentation.formats import formatted
from mcfbench.storage.statuses import reached

TIMING_BASE = (
    "Timings compare schemes fairly only on the same footing: the same solver and "
    "tolerance rule, the same machine, one core each. A DDFV system has about 3 times "
    "the unknowns of a vertex-based scheme (F- and T-vertices)."
)


TIMING_NOTE = TIMING_BASE[:-1] + (
    "; the matrix uses BiCGStab on the refinement series but the robust solver on the "
    "real-world-like meshes, so compare timings within one problem only."
)


FLOAT_FORMAT = "%.10g"
"""The floats of the matrix's and the gallery's CSV tables: ten significant digits."""


# metrics whose exact value is zero besides the ones named "*error*"
ZERO_METRICS = ("max_height", "l2_height", "max_displacement")


# modules that do not change what a run computes (left out of the code digest)
LONG_COLUMNS = ["scheme", "problem", "level", "h", "tau", "steps", "steps_done", "metric",
                "main", "value", "eoc", "eoc_below_accuracy", "reference_accuracy", "status", "t_failed", "min_angle", "max_flipped",
                "t_min_barycentric", "iterations", "cpu_seconds", "robust_status",
                "robust_value", "robust_t_failed", *(
                    f"{monitor}_{when}" for monitor in ("min_angle", "covolume_ratio")
                    for when in ("start", "middle", "end"))]
"""Columns of the long table. ``main``: the metric is its problem's main metric
(:func:`main_metric`, decided here once: the summary, the problem tables, the
plots, the page and the findings take these rows, :func:`main_runs`).
``reference_accuracy``: the relative accuracy the reference answer of the
problem states for its main metric (NaN where none); ``eoc_below_accuracy``:
the row's EOC is not computed, an error of its pair being within it
(:func:`add_eoc`). ``min_angle_*``, ``covolume_ratio_*``: the mesh quality of the run over time
(:func:`quality_over_time`; ``min_angle`` is its worst over the run).
``robust_*``: the re-run of a run that ended with a ``solver_*`` status with
the robust solver, continued from its last accepted state
(:func:`mcfbench.running.batch.robust_fields`; ``robust_status`` empty without a
re-run)."""


def is_error(metric):
    """The metric's exact value is zero (it is an error): EOC applies."""
    return "error" in metric or metric in ZERO_METRICS


def main_metric(problem, available=()):
    """The metric of ``problem`` shown in the summary, the plots and the findings.

    ``problem.main_metric`` (the problem module's) if ``available`` has it (or is
    empty), else the first error among ``available``, else the first of
    ``available``.
    """
    from mcfbench.running.problems import get_problem

    problem = get_problem(problem) if isinstance(problem, str) else problem
    available = list(available)
    named = getattr(problem, "main_metric", None)
    if named and (not available or named in available):
        return named
    errors = [m for m in available if is_error(m)]
    return (errors or available or [""])[0]


def _metric_names(record):
    names = record.get("metric_names")
    if names is None:
        from mcfbench.storage.records import FIELDS

        names = [k for k in record if k not in FIELDS and k != "metric_names"]
    return list(names)


def long_table(records, schemes=None, problems=None, accuracy=None):
    """One row per run and metric (:data:`LONG_COLUMNS`), with the EOC of the errors.

    Parameters
    ----------
    records : iterable of dict
        Run records (:func:`mcfbench.storage.records.read_record`).
    schemes, problems : list of str, optional
        Row order (default: order of first appearance).
    accuracy : dict, optional
        Problem -> the relative accuracy of its reference answer's main metric
        (:func:`mcfbench.studies.matrix.reference_accuracies`): no EOC into it.

    A run without a value of a metric another run of its problem has (a
    scheme that refused the surface) gets a row with NaN.
    """
    import pandas as pd

    by_problem = {}
    for r in records:
        names = by_problem.setdefault(r["problem"], [])
        names.extend(m for m in _metric_names(r) if m not in names)
    main = {problem: main_metric(problem, names) for problem, names in by_problem.items()}
    quality = {id(r): quality_over_time(r) for r in records}
    accuracy = accuracy or {}
    rows = []
    for r in records:
        for metric in by_problem[r["problem"]] or [""]:
            value = r.get(metric, float("nan")) if metric else float("nan")
            rows.append({
                "scheme": r["scheme"], "problem": r["problem"], "level": int(r["level"]),
                "h": r["h"], "tau": r["tau"], "steps": int(r["N"]),
                "steps_done": int(r["steps_done"]), "metric": metric,
                "main": metric == main[r["problem"]], "value": float("nan") if value is None else float(value), "eoc": float("nan"),
                "eoc_below_accuracy": False, "reference_accuracy": accuracy.get(
                    r["problem"], float("nan")) if metric == main[r["problem"]] else float("nan"),
                "status": r["status"], "t_failed": r["t_failed"], "min_angle": r["min_angle"],
                "max_flipped": r["max_flipped"], "t_min_barycentric": r["t_min_barycentric"],
                "iterations": int(r["iterations"]), "cpu_seconds": r["cpu_seconds"],
                **_robust(r, metric), **quality[id(r)]})
    table = pd.DataFrame(rows, columns=LONG_COLUMNS)
    for column in ("h", "tau", "value", "eoc", "reference_accuracy", "t_failed", "min_angle", "max_flipped",
                   "t_min_barycentric", "cpu_seconds", "robust_value", "robust_t_failed",
                   *LONG_COLUMNS[LONG_COLUMNS.index("robust_t_failed") + 1:]):
        table[column] = table[column].astype(float)
    schemes = schemes or list(dict.fromkeys(table["scheme"]))
    problems = problems or list(dict.fromkeys(table["problem"]))
    table = _ordered(table, schemes, problems)
    return add_eoc(table)


def quality_over_time(record):
    """The mesh quality of a run at its start, its middle and its end, from the
    monitor's samples in its record's ``series`` (:func:`mcfbench.running.run.run`).

    ``start``: the first sample (``t = 0``); ``middle``: the last sample at or
    before half the final time ``N tau``, NaN when the run ended before it;
    ``end``: the last state reached (at a breakdown, the state it broke down
    in). NaN where the record has no such series (``covolume_ratio`` before
    it was recorded).

    Returns
    -------
    dict
        ``min_angle_start``, ..., ``covolume_ratio_end`` (:data:`LONG_COLUMNS`).
    """
    series = record.get("series") or {}
    t = np.asarray(series.get("quality_t") or [], dtype=float)
    half = 0.5 * float(record["N"]) * float(record["tau"])
    reached = np.flatnonzero(t <= half * (1 + 1e-9))
    ended = float(record.get("t_end", np.nan))
    middle = reached[-1] if len(reached) and ended >= half * (1 - 1e-9) else None
    out = {}
    for monitor in ("min_angle", "covolume_ratio"):
        values = np.asarray([np.nan if v is None else v for v in series.get(monitor) or []],
                            dtype=float)
        known = len(values) == len(t) and len(t) > 0
        out[f"{monitor}_start"] = values[0] if known else np.nan
        out[f"{monitor}_middle"] = values[middle] if known and middle is not None else np.nan
        out[f"{monitor}_end"] = values[-1] if known else np.nan
    return out


def _robust(record, metric):
    """The robust re-run's columns of one row of the long table."""
    value = (record.get("robust_metrics") or {}).get(metric) if metric else None
    t_failed = record.get("robust_t_failed")
    return {"robust_status": record.get("robust_status") or "",
            "robust_value": float("nan") if value is None else float(value),
            "robust_t_failed": float("nan") if t_failed is None else float(t_failed)}


def main_runs(table, problem):
    """The rows of ``problem``'s main metric (``main``) of the long table, in its
    order, index reset, and the metric's name (``""`` if the problem has no rows)."""
    runs = table[(table["problem"] == problem) & table["main"]].reset_index(drop=True)
    return runs, (runs["metric"].iloc[0] if len(runs) else "")


def solver_only(row):
    """A run (a row of the long table) that ended with a ``solver_*`` status whose
    re-run with the robust solver finished: the failure is the solver's, not the
    scheme's (the re-run reaching its end, the flow's extinction included)."""
    from mcfbench.storage.statuses import REACHED, SOLVER_STATUSES

    return row["status"] in SOLVER_STATUSES and row.get("robust_status", "") in REACHED


def _ordered(table, schemes, problems):
    rank_s = {s: i for i, s in enumerate(schemes)}
    rank_p = {p: i for i, p in enumerate(problems)}
    key = table["problem"].map(rank_p).fillna(len(rank_p)).astype(int) * 10_000 + \
        table["scheme"].map(rank_s).fillna(len(rank_s)).astype(int) * 100
    order = np.lexsort([table.index.to_numpy(), table["level"].to_numpy(), key.to_numpy()])
    return table.iloc[order].reset_index(drop=True)


def add_eoc(table):
    """Fill ``eoc``: ``log2(|e_{k-1}| / |e_k|)`` for error metrics, levels one apart,
    both values finite and non-zero, neither within the row's ``reference_accuracy``
    (:func:`eocs_above_accuracy`; ``eoc_below_accuracy`` marks those); NaN elsewhere."""
    table = table.copy()
    table["eoc"] = np.nan
    table["eoc_below_accuracy"] = False
    if "reference_accuracy" not in table:
        table["reference_accuracy"] = np.nan
    for (_, _, metric), group in table.groupby(["scheme", "problem", "metric"], sort=False):
        if not is_error(metric):
            continue
        group = group.sort_values("level")
        orders, cut = eocs_above_accuracy(group["value"], group["level"],
                                          group["reference_accuracy"])
        table.loc[group.index, "eoc"] = orders
        table.loc[group.index, "eoc_below_accuracy"] = cut
    return table


def eocs_above_accuracy(values, levels, accuracy):
    """The EOCs of one series of errors (:func:`mcfbench.geometry.exact.eoc`), none
    into or out of an error at most the reference's ``accuracy`` (NaN: none stated).

    Returns
    -------
    eocs : (k,) float array
        NaN where :func:`~mcfbench.geometry.exact.eoc` gives none or it is cut.
    cut : (k,) bool array
        The EOCs computable but not computed: an error of the pair within the
        accuracy.
    """
    values = np.asarray(values, dtype=float)
    orders = eoc(values, levels=np.asarray(levels))
    within = np.abs(values) <= np.asarray(accuracy, dtype=float)   # False for NaN
    cut = np.isfinite(orders) & (within | np.r_[False, within[:-1]])
    return np.where(cut, np.nan, orders), cut


BELOW_ACCURACY = "n/a (below the reference's accuracy)"
"""An EOC not computed: an error of its pair within the reference's accuracy."""


def levels_text(levels):
    """``"1-5"`` for consecutive levels, else ``"1, 3"``."""
    levels = sorted(int(v) for v in levels)
    if len(levels) > 2 and levels == list(range(levels[0], levels[-1] + 1)):
        return f"{levels[0]}-{levels[-1]}"
    return ", ".join(str(v) for v in levels)


def breakdown_text(status, t_failed, level=None):
    """``"t_escaped at t = 0.052 (level 3)"``; without the time and the level when they
    are None or NaN (``"extinct"``: the flow's end reached, no level failed)."""
    text = str(status)
    if t_failed is not None and np.isfinite(t_failed):
        text += f" at t = {t_failed:.4g}"
    if level is not None and np.isfinite(level):
        text += f" (level {int(level)})"
    return text


def summary_table(table, problems=None, schemes=None):
    """Problem x scheme: EOC between the two finest finished levels and the
    finest-level value of the problem's main metric, or the breakdown.

    Returns
    -------
    pandas.DataFrame
        Columns ``problem, scheme, metric, error, levels, runs, runs_ok,
        eoc, eoc_below_accuracy, eoc_levels, finest_level, finest_value, status,
        failed_level, t_failed, min_angle, t_min_barycentric,
        cpu_seconds`` (CPU of the finest finished level). ``runs_ok`` counts
        the runs that reached their end, the flow's extinction included
        (:data:`mcfbench.storage.statuses.REACHED`); ``status`` is that of the
        coarsest run that did not, else ``extinct`` when a run ended so, else
        ``ok``. ``eoc`` is NaN and ``eoc_below_accuracy`` true when the finest
        finished level's EOC is not computed, its error or the one before within
        the reference's accuracy (:func:`add_eoc`). The scheme's
        own verdict, with the robust solver's re-run in place of a run whose
        failure it removes (:func:`solver_only`): ``runs_robust_ok``,
        ``robust_eoc``, ``robust_eoc_below_accuracy``, ``robust_eoc_levels``,
        ``robust_finest_level``,
        ``robust_finest_value``. One value a cell: the values by level stay in
        the long table (:func:`with_levels`).
    """
    import pandas as pd

    problems = problems or list(dict.fromkeys(table["problem"]))
    schemes = schemes or list(dict.fromkeys(table["scheme"]))
    rows = []
    for problem in problems:
        part, metric = main_runs(table, problem)
        for scheme in schemes:
            runs = part[part["scheme"] == scheme].sort_values("level")
            if not len(runs):
                continue
            done = runs["status"].map(reached).astype(bool)    # ok, or the flow's extinction
            ok, failed = runs[done], runs[~done]
            # a value is measured when finite: a finished run's, or one taken before
            # a later breakdown (the volume before a pinch)
            finished = runs[np.isfinite(runs["value"])]
            finest = finished.iloc[-1] if len(finished) else None
            eoc_rows = finished[np.isfinite(finished["eoc"])]
            cut = finest is not None and bool(finest["eoc_below_accuracy"])
            last_eoc = eoc_rows.iloc[-1] if len(eoc_rows) and not cut else None
            first_fail = failed.iloc[0] if len(failed) else None
            rows.append({
                "problem": problem, "scheme": scheme, "metric": metric,
                "error": is_error(metric), "levels": levels_text(runs["level"]),
                "runs": len(runs), "runs_ok": len(ok),
                "eoc": np.nan if last_eoc is None else last_eoc["eoc"],
                "eoc_below_accuracy": cut,
                "eoc_levels": "" if last_eoc is None else
                f"{int(last_eoc['level']) - 1}-{int(last_eoc['level'])}",
                "finest_level": np.nan if finest is None else int(finest["level"]),
                "finest_value": np.nan if finest is None else finest["value"],
                "status": first_fail["status"] if first_fail is not None else
                "extinct" if (runs["status"] == "extinct").any() else "ok",
                "failed_level": np.nan if first_fail is None else int(first_fail["level"]),
                "t_failed": np.nan if first_fail is None else first_fail["t_failed"],
                "min_angle": runs["min_angle"].min(),
                "t_min_barycentric": runs["t_min_barycentric"].min(),
                "cpu_seconds": np.nan if finest is None else finest["cpu_seconds"],
                **_robust_summary(runs, metric),
            })
    return pd.DataFrame(rows)


def robust_values(runs):
    """The values of ``runs`` (one scheme on one problem, its main metric, by level),
    each run whose failure the robust solver removes (:func:`solver_only`) replaced by
    its re-run, NaN for the other runs that did not finish."""
    if not len(runs):
        return np.array([])
    fixed = [solver_only(r) for _, r in runs.iterrows()]
    return np.where(fixed, runs["robust_value"],
                    np.where(runs["status"].map(reached).astype(bool), runs["value"], np.nan))


def _robust_summary(runs, metric):
    """The summary's ``robust_*`` columns of one scheme on one problem (its runs of the
    main metric, by level): each run whose failure the robust solver removes replaced
    by its re-run."""
    values = robust_values(runs)
    fixed = sum(solver_only(r) for _, r in runs.iterrows())
    levels = runs["level"].to_numpy()
    eocs, cut = eocs_above_accuracy(values, levels, runs["reference_accuracy"]) \
        if is_error(metric) and len(values) else (np.full(len(values), np.nan), [])
    finite = np.flatnonzero(np.isfinite(values))
    cut = bool(len(finite) and len(cut) and cut[finite[-1]])
    with_eoc = np.flatnonzero(np.isfinite(eocs)) if not cut else []
    return {
        "runs_robust_ok": int(runs["status"].map(reached).sum()) + fixed,
        "robust_eoc": eocs[with_eoc[-1]] if len(with_eoc) else np.nan,
        "robust_eoc_below_accuracy": cut,
        "robust_eoc_levels": f"{int(levels[with_eoc[-1]]) - 1}-{int(levels[with_eoc[-1]])}"
        if len(with_eoc) else "",
        "robust_finest_level": int(levels[finite[-1]]) if len(finite) else np.nan,
        "robust_finest_value": values[finite[-1]] if len(finite) else np.nan,
    }


def error_ratios(summary, problems, floor=0.0):
    """Each scheme's finest-level error relative to the smallest of any scheme that
    finished every level of the problem: the recommendation's score and the
    tangential strategies' accuracy (its geometric mean).

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`summary_table` (or its scheme view: the robust re-runs in place).
    problems : sequence of str
        The problems with an exact error.
    floor : float
        A problem whose smallest error is at most this (exact to round-off) ranks
        no scheme.

    Returns
    -------
    dict
        ``(problem, scheme) -> |finest error| / smallest``, over the schemes that
        finished every level with a finite error.
    """
    ratios = {}
    for p in problems:
        part = summary[(summary["problem"] == p) & np.isfinite(summary["finest_value"])
                       & (summary["runs_ok"] == summary["runs"])]
        best = np.abs(part["finest_value"]).min() if len(part) else np.nan
        if not best > floor:
            continue
        for _, r in part.iterrows():
            ratios[(p, r["scheme"])] = abs(r["finest_value"]) / best
    return ratios


LEVEL_LISTS = ("values", "eocs", "failed", "solver_only", "robust_failed", "robust_values")
"""The columns :func:`with_levels` adds to the summary."""


def with_levels(summary, table):
    """``summary`` with the lists behind its cells, taken from the long table (the
    tidy data: one row per run and metric) at the main metric, by level.

    The columns :data:`LEVEL_LISTS`: ``values`` (every level's value, NaN where none
    was measured), ``eocs`` (every level's EOC but the first's), ``failed`` (the runs
    that did not finish, ``(level, status, t_failed)``), ``solver_only`` (those whose
    failure the robust solver removes, :func:`solver_only`), ``robust_failed`` (the
    re-runs that failed too, ``(level, robust_status, robust_t_failed)``) and
    ``robust_values`` (the values with the robust re-runs in place).
    """
    import pandas as pd

    lists = {name: [] for name in LEVEL_LISTS}
    for problem, scheme in zip(summary["problem"], summary["scheme"]):
        part, _ = main_runs(table, problem)
        runs = part[part["scheme"] == scheme].sort_values("level")
        rows = list(runs.itertuples())
        lists["values"].append([float(v) for v in runs["value"]])
        lists["eocs"].append([float(v) for v in runs["eoc"].iloc[1:]])
        lists["failed"].append([(int(r.level), r.status, r.t_failed) for r in rows
                                if r.status != "ok"])
        lists["solver_only"].append([(int(r.level), r.status, r.t_failed) for r in rows
                                     if solver_only(r._asdict())])
        lists["robust_failed"].append([(int(r.level), r.robust_status, r.robust_t_failed)
                                       for r in rows if r.robust_status not in ("", "ok")])
        lists["robust_values"].append([float(v) for v in robust_values(runs)])
    return summary.assign(**{name: pd.Series(values, index=summary.index, dtype=object)
                             for name, values in lists.items()})


def summary_cell(row):
    """One cell of the summary (a row of :func:`with_levels`): ``"2.01 · 1.23e-03 (L4)"``
    or the breakdown."""
    parts = []
    if row["error"] and np.isfinite(row["eoc"]):
        parts.append(f"EOC {row['eoc']:.2f}")
    elif row["error"] and row["eoc_below_accuracy"]:
        parts.append(f"EOC {BELOW_ACCURACY}")
    if np.isfinite(row["finest_value"]):
        parts.append(f"{row['finest_value']:.3e} (L{int(row['finest_level'])})")
    if row["status"] != "ok":
        parts.append(breakdown_text(row["status"], row["t_failed"], row["failed_level"]))
        if row["solver_only"]:
            parts.append("the robust solver finishes " + (
                "every level" if row["runs_robust_ok"] == row["runs"] else
                "level(s) " + ", ".join(str(level) for level, _, _ in row["solver_only"])))
    return "; ".join(parts) or "–"


def summary_views(summary, table, problems=None, schemes=None, labels=None):
    """The summary as a wide frame (problem rows, scheme columns) of cells; ``table``:
    the long table it was made from."""
    import pandas as pd

    summary = with_levels(summary, table)
    problems = problems or list(dict.fromkeys(summary["problem"]))
    schemes = schemes or list(dict.fromkeys(summary["scheme"]))
    labels = labels or {}
    wide = []
    for problem in problems:
        part = summary[summary["problem"] == problem]
        if not len(part):
            continue
        row = {"problem": f"{problem} ({part['metric'].iloc[0]})"}
        for scheme in schemes:
            hit = part[part["scheme"] == scheme]
            row[labels.get(scheme, scheme)] = summary_cell(hit.iloc[0]) if len(hit) else "–"
        wide.append(row)
    return pd.DataFrame(wide)


def problem_table(table, problem, schemes=None, labels=None):
    """One problem, schemes as rows: the main metric per level, its EOCs, the
    status, the mesh quality over all levels and the finest level's cost."""
    import pandas as pd

    part, metric = main_runs(table, problem)
    schemes = schemes or list(dict.fromkeys(part["scheme"]))
    labels = labels or {}
    levels = sorted(part["level"].unique())
    rows = []
    for scheme in schemes:
        runs = part[part["scheme"] == scheme].sort_values("level").set_index("level")
        if not len(runs):
            continue
        row = {"scheme": labels.get(scheme, scheme)}
        for level in levels:
            if level not in runs.index:
                row[f"L{level}"] = "–"
                continue
            r = runs.loc[level]
            row[f"L{level}"] = formatted(r["value"], ".3e") if reached(r["status"]) and \
                np.isfinite(r["value"]) else r["status"]
        row["EOC"] = ", ".join(BELOW_ACCURACY if cut else formatted(v, ".2f") for v, cut in
                               zip(runs["eoc"].iloc[1:], runs["eoc_below_accuracy"].iloc[1:])) \
            if is_error(metric) and len(runs) > 1 else "–"
        failed = runs[runs["status"] != "ok"]         # an extinction is named too
        row["status"] = "ok" if not len(failed) else "; ".join(
            breakdown_text(r.status, r.t_failed, lv) for lv, r in failed.iterrows())
        finest = runs.iloc[-1]
        row["steps (finest)"] = f"{int(finest['steps_done'])}/{int(finest['steps'])}"
        row["min angle"] = formatted(runs["min_angle"].min(), ".3g")
        row["flipped"] = formatted(runs["max_flipped"].max(), ".0f")
        row["T monitor"] = formatted(runs["t_min_barycentric"].min(), ".3g")
        row["iterations (finest)"] = str(int(finest["iterations"]))
        row["CPU s (finest)"] = formatted(finest["cpu_seconds"], ".3g")
        rows.append(row)
    return pd.DataFrame(rows), metric


SUMMARY_TEXT = ("levels", "eoc_levels", "metric", "status", "robust_eoc_levels")


def read_summary(path):
    """``summary.csv`` back as written (text columns as text, empty as "")."""
    import pandas as pd

    summary = pd.read_csv(path, dtype={c: str for c in SUMMARY_TEXT})
    for column in SUMMARY_TEXT:
        if column in summary:
            summary[column] = summary[column].fillna("")
    for column in ("error", "eoc_below_accuracy", "robust_eoc_below_accuracy"):
        summary[column] = summary[column].astype(bool) if column in summary else False
    return summary


def read_long_table(path):
    """``matrix.csv`` back (metric names and statuses as text, empty as "")."""
    import pandas as pd

    table = pd.read_csv(path, dtype={"metric": str, "status": str, "scheme": str,
                                     "problem": str, "robust_status": str})
    for column in ("metric", "robust_status"):
        table[column] = table[column].fillna("")
    if "eoc_below_accuracy" not in table:      # written before the column
        table["eoc_below_accuracy"], table["reference_accuracy"] = False, np.nan
    return table


