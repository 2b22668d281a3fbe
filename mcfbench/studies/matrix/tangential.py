"""The tangential strategies of the schemes compared from the matrix's tables (issue
#30): survival, accuracy, mesh quality over time and cost per strategy.

A strategy is a scheme's :attr:`mcfbench.running.schemes.Scheme.tangential`
(declared once, in the registry); its row gathers every scheme of the matrix
with it (the ones stepped by another integrator too). Per strategy, over its
schemes and the problems they ran (:func:`strategy_frame`):

- survival: the series (one scheme on one problem, every level) that reached the
  final time on every level, on the refinement series and on the committed real
  meshes apart (the summary's scheme view: a run whose failure the robust solver
  removes counts as finished);
- accuracy: the geometric mean over its schemes and the problems with an exact
  error of the finest-level error relative to the smallest of any scheme there
  (:func:`mcfbench.studies.matrix.tables.error_ratios`, the recommendation's score);
- mesh quality over time: the smallest angle of the triangles and the largest
  ratio of neighbouring covolumes (:func:`mcfbench.geometry.metrics.covolume_ratio`)
  at the start, the middle and the end of the finest level's run
  (:func:`mcfbench.studies.matrix.tables.quality_over_time`), the median over
  its schemes and problems;
- cost: the CPU seconds per step of each run relative to :data:`BASELINE`'s on
  the same problem and level, the median over its runs.

:func:`tangential_section` says it in words, every sentence computed from that
frame.
"""

import numpy as np

from mcfbench.presentation.tables import Table, markdown
from mcfbench.studies.matrix.tables import error_ratios

BASELINE = "cotan"
"""The scheme each run's CPU per step is divided by (same problem and level)."""

WHEN = ("start", "middle", "end")
"""The times of the quality columns (:func:`mcfbench.studies.matrix.tables.quality_over_time`)."""


def strategy_frame(table, summary, strategy_of, real=(), floor=0.0):
    """Survival, accuracy, mesh quality over time and cost per tangential strategy.

    Parameters
    ----------
    table : pandas.DataFrame
        The long table (:func:`mcfbench.studies.matrix.tables.long_table`).
    summary : pandas.DataFrame
        Its summary in the scheme view (:func:`mcfbench.studies.matrix.findings.scheme_view`).
    strategy_of : dict
        Scheme name -> strategy; schemes not in it are left out.
    real : sequence of str
        The committed real meshes among the problems.
    floor : float
        A problem whose smallest error is at most this ranks no scheme
        (:func:`~mcfbench.studies.matrix.tables.error_ratios`).

    Returns
    -------
    pandas.DataFrame
        One row per strategy (in the order of first appearance in
        ``strategy_of``): ``strategy``, ``schemes`` (list), ``series``,
        ``finished``, ``real_series``, ``real_finished``, ``accuracy``,
        ``min_angle_start`` ... ``min_angle_end``, ``covolume_ratio_start`` ...
        ``covolume_ratio_end``, ``cost``; NaN where nothing was measured.
    """
    import pandas as pd

    real = set(real)
    exact = [p for p in dict.fromkeys(summary["problem"])
             if bool(summary[summary["problem"] == p]["error"].any())]
    ratios = error_ratios(summary, exact, floor)
    main = table[table["main"]]
    finest = main.loc[main.groupby(["scheme", "problem"], sort=False)["level"].idxmax()]
    cost = _relative_cost(main)
    rows = []
    for strategy in dict.fromkeys(strategy_of.values()):
        schemes = [s for s in dict.fromkeys(summary["scheme"]) if strategy_of.get(s) == strategy]
        if not schemes:
            continue
        part = summary[summary["scheme"].isin(schemes)]
        done = part["runs_ok"] == part["runs"]
        on_real = part["problem"].isin(real)
        logs = [np.log(r) for (_, s), r in ratios.items() if s in schemes]
        runs = finest[finest["scheme"].isin(schemes)]
        row = {"strategy": strategy, "schemes": schemes,
               "series": int((~on_real).sum()), "finished": int((done & ~on_real).sum()),
               "real_series": int(on_real.sum()), "real_finished": int((done & on_real).sum()),
               "accuracy": float(np.exp(np.mean(logs))) if logs else np.nan,
               "cost": _median(cost[cost["scheme"].isin(schemes)]["relative"])}
        for monitor in ("min_angle", "covolume_ratio"):
            for when in WHEN:
                column = f"{monitor}_{when}"
                row[column] = _median(runs[column]) if column in runs else np.nan
        rows.append(row)
    return pd.DataFrame(rows)


def _median(values):
    values = np.asarray(values, dtype=float)
    values = values[~np.isnan(values)]
    return float(np.median(values)) if len(values) else np.nan


def _relative_cost(main):
    """Per run of the main rows: CPU seconds per step over :data:`BASELINE`'s on the same
    problem and level (``relative``; NaN without a baseline run or without a step)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        per_step = main["cpu_seconds"] / main["steps_done"].where(main["steps_done"] > 0)
    runs = main.assign(per_step=per_step)[["scheme", "problem", "level", "per_step"]]
    base = runs[runs["scheme"] == BASELINE].rename(columns={"per_step": "base"})
    runs = runs.merge(base[["problem", "level", "base"]], on=["problem", "level"], how="left")
    return runs.assign(relative=runs["per_step"] / runs["base"])


def _share(done, total):
    return f"{done} of {total}" if total else "–"


def _trend(row, monitor, spec):
    values = [row[f"{monitor}_{when}"] for when in WHEN]
    return " → ".join("–" if np.isnan(v) else format(v, spec) for v in values)


def strategy_table(frame):
    """The frame of :func:`strategy_frame` as a :class:`~mcfbench.presentation.tables.Table`."""
    rows = [(r["strategy"], ", ".join(r["schemes"]),
             _share(r["finished"], r["series"]), _share(r["real_finished"], r["real_series"]),
             r["accuracy"], _trend(r, "min_angle", ".1f"), _trend(r, "covolume_ratio", ".2f"),
             r["cost"]) for _, r in frame.iterrows()]
    return Table(["strategy", "schemes", "finished (refinement series)",
                  "finished (real meshes)", "error / smallest (geometric mean)",
                  "smallest angle [deg] start → middle → end",
                  "covolume ratio start → middle → end", f"CPU per step / {BASELINE}"],
                 rows, [None, None, None, None, _number, None, None, _number],
                 align="llrrrrrr")


def _number(value):
    return "–" if np.isnan(value) else f"{value:.3g}"


def _extremes(frame, column, largest_best=True):
    """``(best, worst)``: the rows of ``frame`` with the best and with the worst finite
    value of ``column`` (ties together), or ``(None, None)`` when fewer than two
    values are finite or all are equal."""
    known = frame[np.isfinite(frame[column].astype(float))]
    values = known[column].astype(float)
    if len(known) < 2 or values.min() == values.max():
        return None, None
    best = values.max() if largest_best else values.min()
    worst = values.min() if largest_best else values.max()
    return known[values == best], known[values == worst]


def _names(rows, counts=None):
    """``"a"``, ``"a and b"``, ``"a, b and c"``: the strategies of ``rows``; with
    ``counts = (done, total)`` (two columns) each followed by ``" (done of total)"``."""
    names = [r["strategy"] + (f" ({r[counts[0]]} of {r[counts[1]]})" if counts else "")
             for _, r in rows.iterrows()]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " and " + names[-1]


def _verb(rows, singular, plural):
    return plural if len(rows) > 1 else singular


def tangential_section(frame, descriptions=None):
    """The section "Tangential strategies": the table (:func:`strategy_table`) and one
    sentence per quantity naming the best and the worst strategy, each number read
    from ``frame`` (:func:`strategy_frame`); ``descriptions``: strategy -> what it is
    (:data:`mcfbench.running.schemes.TANGENTIAL`). Empty without two strategies."""
    if len(frame) < 2:
        return []
    lines = ["## Tangential strategies", "",
             "The schemes grouped by how they move their vertices along the surface "
             "(`Scheme.tangential` in `mcfbench.running.schemes`). Finished: the series "
             "(one scheme on one problem) that reached the final time on every level. "
             "Error: the finest-level error relative to the smallest of any scheme, "
             "geometric mean over the strategy's schemes and the problems with an exact "
             "error. Mesh quality: the smallest angle of the triangles and the largest ratio "
             "of the covolumes of two neighbouring vertices (1 for equal covolumes; each "
             "scheme's own covolumes) at the start, the middle and the end (the last state "
             "reached) of the finest level's run, median over the strategy's schemes and "
             f"problems. Cost: CPU seconds per step over {BASELINE}'s on the same problem and "
             "level, median over the runs."
             + ("" if not descriptions else " The strategies: " + "; ".join(
                 f"{s}: {descriptions[s]}" for s in frame["strategy"] if s in descriptions)
                + "."), "", markdown(strategy_table(frame)), ""]
    for counts, where in ((("real_finished", "real_series"), "on the real meshes"),
                          (("finished", "series"), "on the refinement series")):
        done, total = (frame[c] for c in counts)
        best, worst = _extremes(frame.assign(share=done / total.where(total > 0)), "share")
        if best is not None:
            lines.append(f"- Survival {where}: the largest share of finished series "
                         f"({best['share'].iloc[0]:.0%}) for {_names(best, counts)}, the "
                         f"smallest ({worst['share'].iloc[0]:.0%}) for "
                         f"{_names(worst, counts)}.")
    best, worst = _extremes(frame, "accuracy", largest_best=False)
    if best is not None:
        lines.append(f"- Accuracy: {_names(best)} {_verb(best, 'has', 'have')} the smallest "
                     f"finest-level errors ({best['accuracy'].iloc[0]:.3g} x the smallest, "
                     f"geometric mean), {_names(worst)} the largest "
                     f"({worst['accuracy'].iloc[0]:.3g} x).")
    for monitor, largest_best, what, unit, spec in (
            ("min_angle", True, "smallest angle", " deg", ".1f"),
            ("covolume_ratio", False, "covolume ratio", "", ".3g")):
        end, start = f"{monitor}_end", f"{monitor}_start"
        best, worst = _extremes(frame, end, largest_best)
        if best is None:
            continue
        b, w = best.iloc[0], worst.iloc[0]
        lines.append(f"- {what.capitalize()} at the end: {_names(best)} "
                     f"{_verb(best, 'keeps', 'keep')} the best (median {b[end]:{spec}}{unit}, "
                     f"from {b[start]:{spec}} at the start), {_names(worst)} the worst "
                     f"({w[end]:{spec}}{unit}, from {w[start]:{spec}}).")
    best, worst = _extremes(frame, "cost", largest_best=False)
    if best is not None:
        lines.append(f"- Cost: {_names(best)} {_verb(best, 'is', 'are')} the cheapest per "
                     f"step ({best['cost'].iloc[0]:.3g} x {BASELINE}, median), "
                     f"{_names(worst)} the most expensive ({worst['cost'].iloc[0]:.3g} x).")
    return lines + [""]
