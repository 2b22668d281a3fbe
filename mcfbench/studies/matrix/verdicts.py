"""The verdicts of the benchmark matrix, from its tables only: the class of each series
(one scheme on one problem: order ~2, converging, not converging, broke down, ...), the
scheme's view of the summary (a failure the robust solver removes is the solver's, not
the scheme's) and the recommendation across problems (:func:`recommend`: candidates
ranked, the schemes left out and why, the recommended scheme's exceptions), worded by
:mod:`mcfbench.studies.matrix.findings`.

The rule of the recommendation: a candidate converges on every problem with an exact
error (at order ~2 wherever at least one scheme reaches order ~2 there; otherwise it
only has to finish every level) and breaks down on none of the real-world-like meshes.
Not held against a scheme, since the numbers cannot tell what limits them: an EOC from
two levels only; an EOC not computed because an error is within the stated accuracy
of the problem's reference (:func:`mcfbench.studies.matrix.tables.add_eoc`); and an
error that stopped decreasing (EOC below the order-2 band) at a value no larger than
that of every scheme showing order ~2 there (a floor of the problem: its stopping rule,
its time error). Candidates are ranked by the geometric mean over those problems of
their finest-level error relative to the smallest one
(:func:`mcfbench.studies.matrix.tables.error_ratios`).
"""

import numpy as np

from mcfbench.studies.matrix.tables import error_ratios

ORDER_BAND = (1.7, 2.3)
"""An EOC in this band counts as order ~2."""

CONVERGING_EOC = 0.5
"""Below this EOC (between the two finest levels) an error is not decreasing."""

WRONG_LIMIT = 10.0
"""A non-decreasing error this many times the smallest of any scheme: a wrong limit."""

TIE = 0.05
"""Candidates whose scores differ by less than this (relative) are called tied."""

ROUNDOFF = 1e-10
"""An error at most this large on every finished level is exact up to round-off."""

ORDER2_ENOUGH = ("order2", "exact", "unsettled", "below_accuracy")
"""Classes that meet the order-2 requirement of a problem where some scheme reaches it."""

FINISHED = ("converging", "not_converging", "exact", "one_level", "unsettled",
            "below_accuracy", "order2")
"""Classes of a series that finished every level."""


def classify(row):
    """``order2``, ``converging``, ``unsettled`` (a decreasing error outside the
    order-2 band measured on two levels only: no order can be read from it),
    ``below_accuracy`` (the finest EOC not computed: an error within the
    reference's accuracy), ``not_converging``, ``one_level``, ``exact``
    (round-off), ``broke_down`` or ``no_error``, of a row of the summary with its
    ``values`` (:func:`mcfbench.studies.matrix.tables.with_levels`). A row whose runs
    broke down but whose error was measured on every level before (the volume before
    a pinch) is judged by it."""
    values = [abs(v) for v in row["values"] if not np.isnan(v)]
    measured = row["error"] and sum(np.isfinite(v) for v in values) == row["runs"]
    if row["runs_ok"] < row["runs"] and not measured:
        return "broke_down"
    if not row["error"]:
        return "no_error"
    if values and all(np.isfinite(v) and v <= ROUNDOFF for v in values):
        return "exact"
    finished = sum(np.isfinite(v) for v in values)
    if not np.isfinite(row["eoc"]):
        if row.get("eoc_below_accuracy", False):
            return "below_accuracy"
        return "one_level" if finished < 2 else "not_converging"
    if ORDER_BAND[0] <= row["eoc"] <= ORDER_BAND[1]:
        return "order2"
    if row["eoc"] < CONVERGING_EOC:
        return "not_converging"
    return "unsettled" if finished == 2 else "converging"


def where(failed):
    """``"level 3: solver_failed at t = 0.03; ..."`` from ``[(3, "solver_failed", 0.03), ...]``."""
    return "; ".join(f"level {lv}: {st}" + (f" at t = {t:.4g}" if not np.isnan(t) else "")
                     for lv, st, t in failed)


def scheme_view(summary):
    """The summary with the robust solver's re-runs in place of the runs whose failure
    they remove, and a ``solver_note`` column saying so.

    A row (of :func:`mcfbench.studies.matrix.tables.with_levels`) whose every
    failure is such a solver failure becomes a finished row (``runs_ok``,
    ``eoc``, ``values``, ``finest_*`` from the ``robust_*`` columns of
    :func:`mcfbench.studies.matrix.tables.summary_table`, ``status`` ``ok``); a
    row with other failures keeps them and only gets the note.
    """
    summary = summary.copy()
    notes = []
    for i, r in summary.iterrows():
        fixed = r["solver_only"]
        if not fixed:
            notes.append("")
            continue
        notes.append(f"A solver verdict, not a scheme verdict: the matrix's solver failed "
                     f"({where(fixed)}) and the robust solver finished "
                     f"{'that run' if len(fixed) == 1 else 'those runs'} when run again.")
        if r["runs_robust_ok"] == r["runs"]:
            for column in ("eoc", "eoc_below_accuracy", "eoc_levels", "finest_level",
                           "finest_value", "values"):
                summary.at[i, column] = r[f"robust_{column}"]
            summary.at[i, "runs_ok"] = r["runs"]
            summary.at[i, "status"] = "ok"
    summary["solver_note"] = notes
    for i, r in summary.iterrows():
        failed = r["robust_failed"]
        if failed:
            summary.at[i, "solver_note"] = (
                r["solver_note"] + " " if r["solver_note"] else "") + (
                f"The robust solver failed too ({where(failed)}): a scheme verdict.")
    return summary


def recommend(summary, problems, schemes, mesh_problems=()):
    """The recommendation's data, every number from the scheme view of the summary.

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`scheme_view` of the summary with its level lists.
    problems, schemes : sequence of str
    mesh_problems : sequence of str
        The real-world-like problems (a breakdown there disqualifies).

    Returns
    -------
    dict
        ``exact``, ``singular``, ``mesh_problems`` (lists of problems: with an exact
        error, without one and not a mesh, the real-world-like ones run);
        ``relaxed`` (the exact problems where no scheme reaches order ~2);
        ``classes`` ((problem, scheme) -> :func:`classify`); ``score`` (scheme ->
        geometric mean of its finest-level error over the smallest, NaN without
        one); ``ranked`` (the candidates, best first); ``tied`` (those within
        :data:`TIE` of the best); ``why_not`` (scheme -> reasons it is left out);
        ``winners`` (problem -> the scheme with the smallest finest-level error
        among those that converge as required there); ``breakdowns`` (scheme ->
        the real-world-like meshes it broke down on); ``exceptions`` (the best
        candidate's problems where it is not the most accurate or its order is not
        ~2: ``problem, class, eoc, ratio, winner, note``).
    """
    verdict = {(r["problem"], r["scheme"]): r for _, r in summary.iterrows()}
    classes = {key: classify(r) for key, r in verdict.items()}
    mesh_problems = [p for p in problems if p in set(mesh_problems)]
    exact = [p for p in problems if bool(summary[summary["problem"] == p]["error"].any())]

    def cls(p, s):
        return classes.get((p, s), "missing")

    needs_order2 = {p: any(cls(p, s) == "order2" for s in schemes) for p in exact}
    floor = {p: min(abs(verdict[(p, s)]["finest_value"]) for s in schemes
                    if cls(p, s) == "order2") for p in exact if needs_order2[p]}

    def at_floor(p, s):
        r = verdict.get((p, s))
        return cls(p, s) in ("converging", "not_converging") and p in floor \
            and np.isfinite(r["eoc"]) and r["eoc"] < ORDER_BAND[0] \
            and abs(r["finest_value"]) <= floor[p]

    def meets(p, s):
        return cls(p, s) in ORDER2_ENOUGH or at_floor(p, s) if needs_order2[p] \
            else cls(p, s) in FINISHED

    winners = {}
    for p in exact:
        good = [s for s in schemes if meets(p, s)]
        if good:
            winners[p] = min(good, key=lambda s: abs(verdict[(p, s)]["finest_value"]))
    breakdowns = {s: [p for p in mesh_problems if cls(p, s) == "broke_down"] for s in schemes}
    why_not = {}
    for s in schemes:
        reasons = []
        for p in exact:
            c = cls(p, s)
            if c in ("missing", "broke_down"):
                reasons.append(f"{'not run' if c == 'missing' else 'broke down'} on {p}")
            elif not meets(p, s):
                eoc = verdict[(p, s)]["eoc"]
                reasons.append(f"EOC {eoc:.2f} on {p}" if np.isfinite(eoc) else
                               f"no EOC on {p}")
        reasons += [f"broke down on {p}" for p in breakdowns[s] if p not in exact]
        if reasons:
            why_not[s] = reasons
    ratios = error_ratios(summary, exact, floor=ROUNDOFF)
    score = {}
    for s in schemes:
        logs = [np.log(ratios[(p, s)]) for p in exact if (p, s) in ratios]
        score[s] = float(np.exp(np.mean(logs))) if logs else float("nan")
    ranked = sorted((s for s in schemes if s not in why_not),
                    key=lambda s: (not np.isfinite(score[s]), score[s]))
    best = ranked[0] if ranked and exact else None
    tied = [s for s in ranked[1:] if score[s] <= (1 + TIE) * score[best]] if best else []
    exceptions = []
    for p in exact if best else ():
        c, r = cls(p, best), verdict[(p, best)]
        note = ("EOC not computed (an error within the reference's accuracy)"
                if c == "below_accuracy" else
                "from two levels only: the order is not settled" if c == "unsettled" else
                "at an error no larger than any scheme of order ~2 there (a floor)"
                if at_floor(p, best) else
                "not ~2" + ("" if needs_order2[p] else " (no scheme reaches order ~2 there)")
                if c in ("converging", "not_converging", "one_level") else "")
        if note or winners.get(p) != best:
            exceptions.append({"problem": p, "class": c, "eoc": r["eoc"],
                               "ratio": ratios.get((p, best), np.nan),
                               "winner": winners.get(p, ""), "note": note})
    return {"exact": exact, "mesh_problems": mesh_problems,
            "singular": [p for p in problems if p not in exact and p not in mesh_problems],
            "relaxed": [p for p in exact if not needs_order2[p]], "classes": classes,
            "score": score, "ranked": ranked if exact else [], "tied": tied,
            "why_not": why_not, "winners": winners, "breakdowns": breakdowns,
            "exceptions": exceptions}
