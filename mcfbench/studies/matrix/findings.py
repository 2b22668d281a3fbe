"""The findings of the benchmark matrix in words, from its tables only (the summary and
the long table, whose rows give each level's value): which scheme converges at which
order on which problem, which breaks down where, and the recommendation.

A verdict is the scheme's, not its linear solver's: a run that ended with a
``solver_*`` status and that the scheme's robust solver
(:attr:`mcfbench.running.schemes.Scheme.robust_solver`, recorded as ``robust_solver``)
finished when continued (:func:`mcfbench.running.batch.run_spec`) counts as finished, with the
robust run's value, and its text says that the failure was the solver's
(:func:`scheme_view`)."""

from pathlib import Path

import numpy as np

from mcfbench.presentation.formats import formatted
from mcfbench.studies.matrix import mesh_problems, reference_accuracies
from mcfbench.studies.matrix.tables import (
    error_ratios,
    levels_text,
    is_error,
    main_runs,
    read_long_table,
    read_summary,
    summary_table,
    with_levels,
)

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


NOISE_SECONDS = 0.01
"""CPU times below this are at the noise level of the clock and the start-up: not ranked."""


def _number(value):
    """A metric's value as the tables show it (``tables.summary_cell``): one unit
    per quantity, no percentages."""
    return f"{value:.3e}"


def _seconds(value):
    return f"{value:.3g} s" + (" (noise level)" if value < NOISE_SECONDS else "")


def _classify(row):
    """``order2``, ``converging``, ``unsettled`` (a decreasing error outside the
    order-2 band measured on two levels only: no order can be read from it),
    ``not_converging``, ``one_level``, ``exact`` (round-off), ``broke_down`` or
    ``no_error``. A row whose runs broke down but whose error was
    measured on every level before (the volume before a pinch) is judged by it."""
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
        return "one_level" if finished < 2 else "not_converging"
    if ORDER_BAND[0] <= row["eoc"] <= ORDER_BAND[1]:
        return "order2"
    if row["eoc"] < CONVERGING_EOC:
        return "not_converging"
    return "unsettled" if finished == 2 else "converging"


def cheapest_to_reach(table):
    """Work-precision verdicts: per problem with an error metric, the target error
    ``E`` = the largest of the schemes' smallest errors (so every scheme with a
    finite error reaches it), and for each scheme the fewest CPU seconds of a run
    whose ``|error| <= E``.

    Parameters
    ----------
    table : pandas.DataFrame
        The long table (:func:`mcfbench.studies.matrix.tables.long_table`).

    Returns
    -------
    list of dict
        ``problem, metric, target, costs`` (scheme -> CPU seconds, cheapest first).
    """
    rows = []
    for problem in dict.fromkeys(table["problem"]):
        runs, metric = main_runs(table, problem)
        runs = runs[np.isfinite(runs["value"])]
        if not is_error(metric) or runs.empty:
            continue
        runs = runs.assign(error=np.abs(runs["value"]))
        best = runs.groupby("scheme", sort=False)["error"].min()
        target = float(best.max())
        reach = runs[runs["error"] <= target].groupby("scheme", sort=False)["cpu_seconds"].min()
        rows.append({"problem": problem, "metric": metric, "target": target,
                     "costs": dict(sorted(reach.items(), key=lambda kv: kv[1]))})
    return rows


def work_precision_section(rows):
    """The work-precision verdicts of :func:`cheapest_to_reach` in words; CPU times
    below :data:`NOISE_SECONDS` are marked, and a problem whose two cheapest runs are
    both below it is not ranked."""
    lines = ["## Accuracy per CPU second", "",
             "To reach the error every scheme with a finite error reaches on a problem "
             "(the largest of their smallest errors), the cheapest run of each scheme, in CPU "
             "seconds on one core with the problem's solver rule for every scheme (the same "
             "footing within a problem; `figures/work_precision.png`). A time below "
             f"{1000 * NOISE_SECONDS:.0f} ms is at the noise level of the clock and is not "
             "ranked:", ""]
    for r in rows:
        costs = list(r["costs"].items())
        if not costs:
            continue
        head = f"- {r['problem']} ({r['metric']} <= {_number(r['target'])}): "
        if costs[min(1, len(costs) - 1)][1] < NOISE_SECONDS:
            lines.append(head + "no ranking, the cheapest runs are at the noise level: "
                         + ", ".join(f"{s} {_seconds(c)}" for s, c in costs) + ".")
            continue
        (first, seconds), rest = costs[0], ", ".join(f"{s} {_seconds(c)}" for s, c in costs[1:])
        lines.append(head + f"**{first}** is the cheapest, {_seconds(seconds)}"
                     + (f" (then {rest})." if rest else "."))
    return lines + [""]


def _where(failed):
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
                     f"({_where(fixed)}) and the robust solver finished "
                     f"{'that run' if len(fixed) == 1 else 'those runs'} when run again.")
        if r["runs_robust_ok"] == r["runs"]:
            for column in ("eoc", "eoc_levels", "finest_level", "finest_value", "values"):
                summary.at[i, column] = r[f"robust_{column}"]
            summary.at[i, "runs_ok"] = r["runs"]
            summary.at[i, "status"] = "ok"
    summary["solver_note"] = notes
    for i, r in summary.iterrows():
        failed = r["robust_failed"]
        if failed:
            summary.at[i, "solver_note"] = (
                r["solver_note"] + " " if r["solver_note"] else "") + (
                f"The robust solver failed too ({_where(failed)}): a scheme verdict.")
    return summary


def scope_lines(plan, all_schemes, all_problems, labels=None):
    """What the matrix ran: full (every scheme and problem of the registries) or cut
    down, at which levels, and the schemes' labels beside their registry names.

    Parameters
    ----------
    plan : dict
        :func:`mcfbench.studies.matrix.plan.plan` (``schemes``, ``problems``: name ->
        levels, ``selected``).
    all_schemes, all_problems : sequence of str
        The registries' names.
    labels : dict, optional
        Scheme name -> label.
    """
    from mcfbench.running.schemes import split_name

    labels = labels or {}
    schemes, problems = list(plan["schemes"]), dict(plan["problems"])
    base = {split_name(s)[0] for s in schemes}
    full = (not plan.get("selected") and set(all_schemes) <= base
            and set(all_problems) <= set(problems))
    levels = "; ".join(f"{p} {levels_text(k)}" for p, k in problems.items())
    if full:
        text = (f"Scope: the full matrix, every scheme of the registry ({len(schemes)} with "
                f"the other integrators) on every problem ({len(problems)}), at the levels "
                f"{levels}.")
    else:
        text = (f"Scope: a cut-down matrix{' (`matrix.select`)' if plan.get('selected') else ''}"
                f": {len(schemes)} scheme(s) ({', '.join(schemes)}; the registry has "
                f"{len(all_schemes)}) on {len(problems)} of the {len(all_problems)} problems, "
                f"at the levels {levels}. The verdicts and the recommendation below hold for "
                "this selection only.")
    named = [f"{s} ({labels[s]})" for s in schemes if labels.get(s) not in (None, s)]
    return [text, ""] + (["Schemes are named as in the registry "
                          "(`mcfbench.running.schemes.SCHEMES`), with their labels: "
                          + ", ".join(named) + ".", ""] if named else [])


def matrix_findings(table, summary=None, labels=None, mesh_problems=(),
                    source="tables/summary.csv", work_precision=(), scope=(), accuracy=None):
    """The findings, Markdown, written from the tables only.

    Parameters
    ----------
    table : pandas.DataFrame
        The long table (:func:`mcfbench.studies.matrix.tables.long_table`, or
        ``matrix.csv`` read back): each level's value of the main metric.
    summary : pandas.DataFrame, optional
        Its summary (``summary.csv`` read back; default: :func:`summary_table` of
        ``table``).
    labels : dict, optional
        Scheme name -> label.
    mesh_problems : sequence of str
        The real-world-like problems (no refinement series).
    work_precision : list of dict
        :func:`cheapest_to_reach` of the long table (a section when given).
    scope : list of str
        :func:`scope_lines` (after the introduction).
    accuracy : dict, optional
        Problem -> the relative accuracy of its reference answer, where it states one
        (:func:`mcfbench.studies.matrix.reference_accuracies`).
    """
    summary = scheme_view(with_levels(summary_table(table) if summary is None else summary,
                                      table))
    problems = list(dict.fromkeys(summary["problem"]))
    schemes = list(dict.fromkeys(summary["scheme"]))
    lines = ["# Findings of the benchmark matrix", "",
             f"Written by `mcfbench.studies.matrix.findings` from `{source}`: every number below "
             "is read from the tables, none typed by hand. Order ~2 means an EOC between "
             f"the two finest finished levels in [{ORDER_BAND[0]}, {ORDER_BAND[1]}]; an "
             f"error with EOC below {CONVERGING_EOC} is not decreasing; an EOC from two "
             "levels only settles no order and disqualifies no scheme. Values are "
             "numbers as in the tables (a relative error too, not a percentage).", "",
             *scope]
    verdict = {}
    lines += ["## Per problem", ""]
    for problem in problems:
        part = summary[summary["problem"] == problem].copy()
        part["class"] = [_classify(r) for _, r in part.iterrows()]
        metric = part["metric"].iloc[0]
        kind = "real-world-like mesh" if problem in mesh_problems else \
            "refinement series" if part["error"].iloc[0] else "refinement series, no exact value"
        done = part[(part["runs_ok"] == part["runs"]) & np.isfinite(part["finest_value"])]
        smallest = np.abs(done["finest_value"]).min() if len(done) else np.nan
        lines += [f"### {problem}", "",
                  f"Main metric `{metric}`; levels {part['levels'].iloc[0]} ({kind}).", ""]
        for _, r in part.iterrows():
            verdict[(problem, r["scheme"])] = r
            name = f"**{r['scheme']}**"
            values = list(r["values"])
            shown = ", ".join(_number(v) if np.isfinite(v) else "–" for v in values)
            eocs = ", ".join(formatted(v, ".2f", missing="") for v in r["eocs"])
            if r["class"] == "order2":
                two = " from two levels only" if sum(np.isfinite(values)) == 2 else ""
                text = (f"{name} converges at order ~2{two}: EOC {r['eoc']:.2f} (levels "
                        f"{r['eoc_levels']}), finest error {_number(r['finest_value'])}"
                        f" (level {int(r['finest_level'])}); errors {shown}.")
            elif r["class"] == "converging":
                text = (f"{name} converges at order {r['eoc']:.2f} (levels {r['eoc_levels']}),"
                        f" not ~2; errors {shown}.")
            elif r["class"] == "unsettled":
                text = (f"{name} converges, EOC {r['eoc']:.2f} (levels {r['eoc_levels']}): "
                        f"from two levels only, the order is not settled; errors {shown}.")
            elif r["class"] == "not_converging":
                text = (f"{name} does not converge: the error is not decreasing (EOCs "
                        f"{eocs or '–'}; errors {shown})")
                ratio = abs(r["finest_value"]) / smallest if smallest > 0 else \
                    np.inf if smallest == 0 else np.nan   # nan: no scheme finished
                if ratio >= WRONG_LIMIT:
                    text += (f": it converges to another surface (finest error {ratio:.3g} x "
                             "the smallest of any scheme).")
                else:
                    text += "."
            elif r["class"] == "one_level":
                text = (f"{name}: one finished level only ({metric} {shown}), no EOC.")
            elif r["class"] == "exact":
                text = (f"{name} is exact up to round-off: {metric} at most "
                        f"{max(abs(v) for v in values):.2e} on every level.")
            elif r["class"] == "no_error":
                text = (f"{name} finished every level; {metric} at the finest level "
                        f"{r['finest_value']:.4g}.")
            else:
                text = (f"{name} broke down in {r['runs'] - r['runs_ok']} of {r['runs']} runs "
                        f"({_where(r['failed'])}).")
                if np.isfinite(r["finest_value"]):
                    text += (f" Finished levels: {metric} {shown}"
                             + (f", EOC {r['eoc']:.2f}" if np.isfinite(r["eoc"]) else "") + ".")
            if np.isfinite(r["t_min_barycentric"]):
                text += f" Smallest T monitor {r['t_min_barycentric']:.3g}."
            if r["solver_note"]:
                text += " " + r["solver_note"]
            lines.append("- " + text)
        lines += _common_floor(part, metric)
        lines.append("")
    if work_precision:
        lines += work_precision_section(work_precision)
    lines += real_mesh_section(summary, verdict, problems, schemes)
    lines += tangential_lines(table, summary, problems, schemes)
    lines += recommendation(summary, verdict, problems, schemes, mesh_problems, accuracy)
    solver = summary[[bool(fixed) for fixed in summary["solver_only"]]]
    if len(solver):
        lines += ["## Solver verdicts", "",
                  "Runs whose failure the robust solver removes: the failure belongs to "
                  "the linear solver on that system, not to the scheme, and the verdicts "
                  "above count those runs as finished with the robust solver's values: "
                  + "; ".join(f"{r['scheme']} on {r['problem']} ({_where(r['solver_only'])})"
                              for _, r in solver.iterrows() if r["solver_only"]) + ".", ""]
    return "\n".join(lines).rstrip() + "\n"


def _common_floor(part, metric):
    """A remark when no scheme's error decreases and all finish with about the
    same error: the floor belongs to the problem, not to a scheme."""
    finished = part[part["class"].isin(["not_converging", "converging"])]
    if len(finished) < 2 or (part["class"] == "order2").any() \
            or not (finished["class"] == "not_converging").all():
        return []
    values = np.abs(finished["finest_value"].to_numpy(dtype=float))
    spread = values.max() / values.min() if values.min() > 0 else np.inf
    if not spread < 2.0:
        return []
    return ["", f"No scheme's error decreases at order ~2 here, and the {len(finished)} schemes "
                f"that finished end within a factor {spread:.2f} of each other "
                f"({values.min():.3e} to {values.max():.3e}): an error floor common to all "
                "schemes (the problem's stopping rule or time error), not a property of one "
                "scheme."]


def real_mesh_section(summary, verdict, problems, schemes):
    """The section "On the real meshes": per scheme, on how many of the committed real
    meshes it reached the final time on every level, and the median magnitude of its
    finest-level error against the references there (the real meshes also count as
    real-world-like meshes in the recommendation: a breakdown there disqualifies)."""
    real = real_meshes(problems)
    if not real:
        return []
    lines = ["## On the real meshes", "",
             f"The committed real meshes run ({', '.join(real)}; references from the "
             "finest levels of two schemes, `mcfbench/data/meshes/README.md`): per scheme, "
             "the meshes on which it reached the final time on every level, and the median "
             "magnitude of its finest-level error there.", ""]
    for s in schemes:
        rows = [verdict[(p, s)] for p in real if (p, s) in verdict]
        if not rows:
            continue
        done = [r for r in rows if r["runs_ok"] == r["runs"]]
        errors = [abs(r["finest_value"]) for r in done if np.isfinite(r["finest_value"])]
        broke = [f"{r['problem']}" for r in rows if r["runs_ok"] < r["runs"]]
        text = f"- **{s}**: {len(done)} of {len(rows)}"
        if errors:
            text += f", median error {_number(float(np.median(errors)))}"
        if broke:
            text += f"; broke down on {', '.join(broke)}"
        lines.append(text + ".")
    return lines + [""]


def real_meshes(problems):
    """The committed real meshes among ``problems`` (names of the registry)."""
    from mcfbench.running.problems import get_problem
    from mcfbench.studies.matrix import is_real_mesh

    return [p for p in problems if is_real_mesh(get_problem(p))]


def tangential_lines(table, summary, problems, schemes):
    """The section "Tangential strategies" (:mod:`mcfbench.studies.matrix.tangential`)
    of the registry's schemes among ``schemes``, grouped by their
    :attr:`~mcfbench.running.schemes.Scheme.tangential`."""
    from mcfbench.running.schemes import TANGENTIAL, find_scheme
    from mcfbench.studies.matrix.tangential import strategy_frame, tangential_section

    entries = {s: find_scheme(s) for s in schemes}
    strategy_of = {s: e.tangential for s, e in entries.items() if e is not None}
    frame = strategy_frame(table, summary, strategy_of, real_meshes(problems), ROUNDOFF)
    return tangential_section(frame, TANGENTIAL)


def recommendation(summary, verdict, problems, schemes, mesh_problems, accuracy=None):
    """The section "Across problems".

    A candidate converges on every problem with an exact error (at order ~2
    wherever at least one scheme reaches order ~2 there; otherwise it only
    has to finish every level) and breaks down on none of the
    real-world-like meshes. Two EOCs are not held against a scheme (the
    recommendation says so), since the numbers cannot tell what limits them:
    one into a finest-level error within the stated accuracy of the problem's
    reference (``accuracy``: a reference computed by schemes, the real
    meshes'), and one of an error that stopped decreasing (EOC below the
    order-2 band) at a value no larger than that of every scheme showing
    order ~2 there (a floor of the problem: its stopping rule, its time
    error). Candidates are ranked by the geometric mean over
    those problems of their finest-level error relative to the smallest
    one. The problems without an exact value (singular flows such as a
    pinching torus) only inform: which scheme reaches the latest time.
    """
    accuracy = accuracy or {}
    mesh_problems = [p for p in problems if p in set(mesh_problems)]
    exact = [p for p in problems if bool(summary[summary["problem"] == p]["error"].any())]
    singular = [p for p in problems if p not in exact and p not in mesh_problems]
    lines = ["## Across problems", ""]
    if not exact:
        return lines + ["No problem with an exact error was run: no recommendation.", ""]
    lines.append(f"Problems with an exact error: {', '.join(exact)}. Real-world-like meshes "
                 f"(a breakdown disqualifies): {', '.join(mesh_problems) or 'none run'}. "
                 f"Without an exact value (breakdown times only): "
                 f"{', '.join(singular) or 'none'}.")
    lines.append("")

    def cls(p, s):
        return _classify(verdict[(p, s)]) if (p, s) in verdict else "missing"

    needs_order2 = {p: any(cls(p, s) == "order2" for s in schemes) for p in exact}
    floor = {p: min(abs(verdict[(p, s)]["finest_value"]) for s in schemes
                    if cls(p, s) == "order2") for p in exact if needs_order2[p]}

    def at_floor(p, s):
        """Why the EOC of ``s`` on ``p`` cannot be judged (empty if it can)."""
        if cls(p, s) not in ("converging", "not_converging"):
            return ""
        r = verdict[(p, s)]
        error = abs(r["finest_value"])
        if error <= accuracy.get(p, -np.inf):
            return "into an error within the reference's accuracy"
        if p in floor and np.isfinite(r["eoc"]) and r["eoc"] < ORDER_BAND[0] \
                and error <= floor[p]:
            return "at an error no larger than that of any scheme of order ~2 there (a floor)"
        return ""

    relaxed = [p for p in exact if not needs_order2[p]]
    if relaxed:
        lines.append(f"No scheme reaches order ~2 on {', '.join(relaxed)}: there a scheme "
                     "only has to finish every level.")
        lines.append("")
    winners = {}
    for p in exact:
        good = [s for s in schemes if cls(p, s) in ORDER2_ENOUGH or at_floor(p, s)] \
            if needs_order2[p] \
            else [s for s in schemes if cls(p, s) in ("converging", "not_converging", "exact",
                                                      "one_level", "unsettled")]
        if good:
            winners[p] = min(good, key=lambda s: abs(verdict[(p, s)]["finest_value"]))
    candidates, why_not = [], {}
    for s in schemes:
        reasons = []
        for p in exact:
            c = cls(p, s)
            if c == "missing":
                reasons.append(f"not run on {p}")
            elif c == "broke_down":
                reasons.append(f"broke down on {p}")
            elif needs_order2[p] and c not in ORDER2_ENOUGH and not at_floor(p, s):
                eoc = verdict[(p, s)]["eoc"]
                reasons.append(f"EOC {eoc:.2f} on {p}" if np.isfinite(eoc) else
                               f"no EOC on {p}")
        for p in mesh_problems:
            if p not in exact and (p, s) in verdict and cls(p, s) == "broke_down":
                reasons.append(f"broke down on {p}")
        if reasons:
            why_not[s] = reasons
        else:
            candidates.append(s)
    # exact to round-off somewhere: no ranking by that problem
    ratios = error_ratios(summary, exact, floor=ROUNDOFF)

    def geometric_mean(s):
        logs = [np.log(ratios[(p, s)]) for p in exact if (p, s) in ratios]
        return float(np.exp(np.mean(logs))) if logs else float("nan")

    if candidates:
        score = {s: geometric_mean(s) for s in candidates}
        ranked = sorted(candidates, key=lambda s: (not np.isfinite(score[s]), score[s]))
        best = ranked[0]
        lines.append("Converge as required on every problem with an exact error and do not "
                     "break down on the real-world-like meshes: " + ", ".join(
                         f"{s} (finest-level errors {score[s]:.3g} x the smallest, geometric "
                         "mean)" for s in ranked) + ".")
        lines.append("")
        tied = [s for s in ranked[1:] if score[s] <= (1 + TIE) * score[best]]
        if tied:
            lines.append(f"{best} and {', '.join(tied)} are practically tied (scores within "
                         f"{100 * TIE:.0f} %): either is a sound choice.")
            lines.append("")
        beaten = [f"{p}: {winners[p]}" for p in exact if winners.get(p) not in (None, best)]
        lines.append(f"**Recommendation: {best}**" + (
            ", with the smallest finest-level error on every problem with an exact error."
            if not beaten else
            ", the smallest finest-level errors on average among them, though not on every "
            "problem (smallest elsewhere: " + "; ".join(beaten) + ").")
            + _order_caveat(best, exact, cls, verdict, needs_order2, at_floor))
    else:
        lines.append("**No scheme wins everywhere**: none converges as required on every "
                     "problem with an exact error without breaking down on a real-world-like "
                     "mesh.")
    lines.append("")
    lines.append("Smallest finest-level error per problem (among the schemes that converge as "
                 "required there): " + "; ".join(f"{p}: {winners.get(p, 'none')}"
                                                 for p in exact) + ".")
    if why_not:
        lines.append("")
        lines.append("Left out: " + "; ".join(f"{s} ({', '.join(r)})"
                                              for s, r in why_not.items()) + ".")
    if singular:
        lines.append("")
        for p in singular:
            done = [s for s in schemes if (p, s) in verdict and cls(p, s) != "broke_down"]
            times = {s: verdict[(p, s)]["t_failed"] for s in schemes if (p, s) in verdict
                     and cls(p, s) == "broke_down" and np.isfinite(verdict[(p, s)]["t_failed"])}
            text = f"On {p} "
            text += (f"{', '.join(done)} finished every level" if done else
                     "every scheme broke down")
            if times:
                latest = max(times, key=times.get)
                text += ("; " if done else ", ") + f"the latest breakdown: {latest} at t = " \
                    f"{times[latest]:.4g} (earliest: {min(times, key=times.get)} at t = " \
                    f"{min(times.values()):.4g}; coarsest failing level)"
            lines.append(text + ".")
    return lines + [""]


ORDER2_ENOUGH = ("order2", "exact", "unsettled")
"""Classes that meet the order-2 requirement of a problem where some scheme reaches it."""


def _order_caveat(scheme, exact, cls, verdict, needs_order2, at_floor):
    """What the recommendation of ``scheme`` does not claim: its orders that are not ~2,
    in the words of the per-problem verdicts."""
    notes = []
    for p in exact:
        c, eoc = cls(p, scheme), verdict[(p, scheme)]["eoc"]
        if at_floor(p, scheme):
            notes.append(f"EOC {eoc:.2f} on {p}, {at_floor(p, scheme)}")
        elif c == "unsettled":
            notes.append(f"EOC {eoc:.2f} on {p} from two levels only (the order is not settled)")
        elif c in ("converging", "not_converging", "one_level"):
            notes.append((f"EOC {eoc:.2f} on {p}, not ~2" if np.isfinite(eoc) else
                          f"no EOC on {p}")
                         + ("" if needs_order2[p] else " (no scheme reaches order ~2 there)"))
    return (" It does not show order ~2 everywhere: " + "; ".join(notes) + ".") if notes else ""


def findings(summary_csv, long_csv, out, plan):
    """``findings.md`` from ``summary.csv`` and the long table ``matrix.csv`` (each
    level's value, the cost of accuracy): numbers from the tables only."""
    from mcfbench.running.problems import PROBLEMS
    from mcfbench.running.schemes import SCHEMES, scheme_label
    from mcfbench.storage.atomic import write_text

    table = read_long_table(long_csv)
    labels = {s: scheme_label(s) for s in plan["schemes"]}
    text = matrix_findings(table, read_summary(summary_csv), labels, mesh_problems(plan),
                           source=Path(summary_csv).as_posix(),
                           work_precision=cheapest_to_reach(table),
                           scope=scope_lines(plan, list(SCHEMES), list(PROBLEMS), labels),
                           accuracy=reference_accuracies(plan))
    write_text(out, text)
    return text
