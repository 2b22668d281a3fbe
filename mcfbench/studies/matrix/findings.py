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
from mcfbench.presentation.tables import Table, markdown
from mcfbench.studies.matrix import mesh_problems
from mcfbench.studies.matrix.remeshed import remeshed_pairs, remeshing_frame, remeshing_section
from mcfbench.studies.matrix.singularities import singularity_section
from mcfbench.studies.matrix.tables import (
    BELOW_ACCURACY,
    is_error,
    levels_text,
    main_runs,
    read_long_table,
    read_summary,
    summary_table,
    with_levels,
)
from mcfbench.studies.matrix.verdicts import (
    CONVERGING_EOC,
    ORDER_BAND,
    ROUNDOFF,
    TIE,
    WRONG_LIMIT,
    classify,
    recommend,
    scheme_view,
    where,
)

NOISE_SECONDS = 0.01
"""CPU times below this are at the noise level of the clock and the start-up: not ranked."""


def _number(value):
    """A metric's value as the tables show it (``tables.summary_cell``): one unit
    per quantity, no percentages."""
    return f"{value:.3e}"


def _seconds(value):
    return f"{value:.3g} s" + (" (noise level)" if value < NOISE_SECONDS else "")


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
                    source="tables/summary.csv", work_precision=(), scope=()):
    """The findings, Markdown, written from the tables only: the verdict across
    problems first (:func:`verdict_section`), then the detail behind it.

    Parameters
    ----------
    table : pandas.DataFrame
        The long table (:func:`mcfbench.studies.matrix.tables.long_table`, or
        ``matrix.csv`` read back): each level's value of the main metric, and its
        EOCs, none into an error within a reference's accuracy.
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
    """
    summary = scheme_view(with_levels(summary_table(table) if summary is None else summary,
                                      table))
    problems = list(dict.fromkeys(summary["problem"]))
    schemes = list(dict.fromkeys(summary["scheme"]))
    verdict = {(r["problem"], r["scheme"]): r for _, r in summary.iterrows()}
    lines = ["# Findings of the benchmark matrix", "",
             f"Written by `mcfbench.studies.matrix.findings` from `{source}`: every number below "
             "is read from the tables, none typed by hand. Order ~2 means an EOC between "
             f"the two finest finished levels in [{ORDER_BAND[0]}, {ORDER_BAND[1]}]; an "
             f"error with EOC below {CONVERGING_EOC} is not decreasing; an EOC from two "
             "levels only settles no order and disqualifies no scheme; no EOC is computed "
             "into an error within the stated accuracy of a problem's reference (n/a). "
             "Values are numbers as in the tables (a relative error too, not a percentage).", "",
             *scope]
    lines += verdict_section(recommend(summary, problems, schemes, mesh_problems), schemes,
                             verdict)
    lines += ["## Per problem", ""]
    for problem in problems:
        lines += problem_lines(summary[summary["problem"] == problem].copy(), problem,
                               mesh_problems)
    if work_precision:
        lines += work_precision_section(work_precision)
    lines += real_mesh_section(summary, verdict, problems, schemes)
    lines += remeshing_section(remeshing_frame(table, summary, remeshed_pairs(schemes)))
    lines += singularity_section(table)
    lines += tangential_lines(table, summary, problems, schemes)
    solver = summary[[bool(fixed) for fixed in summary["solver_only"]]]
    if len(solver):
        lines += ["## Solver verdicts", "",
                  "Runs whose failure the robust solver removes: the failure belongs to "
                  "the linear solver on that system, not to the scheme, and the verdicts "
                  "above count those runs as finished with the robust solver's values: "
                  + "; ".join(f"{r['scheme']} on {r['problem']} ({where(r['solver_only'])})"
                              for _, r in solver.iterrows() if r["solver_only"]) + ".", ""]
    return "\n".join(lines).rstrip() + "\n"


def problem_lines(part, problem, mesh_problems):
    """The verdict of every scheme on one problem (``part``: its rows of the scheme
    view of the summary), one line each, as ``### problem`` and a list."""
    part["class"] = [classify(r) for _, r in part.iterrows()]
    metric = part["metric"].iloc[0]
    kind = "real-world-like mesh" if problem in mesh_problems else \
        "refinement series" if part["error"].iloc[0] else "refinement series, no exact value"
    done = part[(part["runs_ok"] == part["runs"]) & np.isfinite(part["finest_value"])]
    smallest = np.abs(done["finest_value"]).min() if len(done) else np.nan
    lines = [f"### {problem}", "",
             f"Main metric `{metric}`; levels {part['levels'].iloc[0]} ({kind}).", ""]
    for _, r in part.iterrows():
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
        elif r["class"] == "below_accuracy":
            text = (f"{name} reaches an error within the reference's accuracy, finest "
                    f"{_number(r['finest_value'])} (level {int(r['finest_level'])}): "
                    f"EOC {BELOW_ACCURACY}; errors {shown}.")
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
                    f"({where(r['failed'])}).")
            if np.isfinite(r["finest_value"]):
                text += (f" Finished levels: {metric} {shown}"
                         + (f", EOC {r['eoc']:.2f}" if np.isfinite(r["eoc"]) else "") + ".")
        if np.isfinite(r["t_min_barycentric"]):
            text += f" Smallest T monitor {r['t_min_barycentric']:.3g}."
        if r["solver_note"]:
            text += " " + r["solver_note"]
        lines.append("- " + text)
    return lines + _common_floor(part, metric) + [""]


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
    :attr:`~mcfbench.running.schemes.Scheme.tangential`; the schemes that change
    their mesh (``NAME+remesh``: :func:`remeshing_section`) are left out, their
    tangential motion being their scheme's."""
    from mcfbench.running.schemes import TANGENTIAL, find_scheme
    from mcfbench.studies.matrix.tangential import strategy_frame, tangential_section

    entries = {s: find_scheme(s) for s in schemes}
    strategy_of = {s: e.tangential for s, e in entries.items()
                   if e is not None and e.mesh_strategy == "none"}
    frame = strategy_frame(table, summary, strategy_of, real_meshes(problems), ROUNDOFF)
    return tangential_section(frame, TANGENTIAL)


def _count(n, noun):
    """``"1 problem"``, ``"3 problems"``, ``"2 meshes"``."""
    return f"{n} {noun}" + ("" if n == 1 else "es" if noun.endswith("sh") else "s")


def verdict_section(rec, schemes, verdict):
    """The section "Across problems": the verdict in a few sentences (which scheme and
    why, in the numbers of :func:`~mcfbench.studies.matrix.verdicts.recommend`: the
    ranking's geometric mean, the breakdowns on the real-world-like meshes), then as
    tables every scheme's standing and the recommended scheme's exceptions, and the
    latest breakdown on each problem without an exact value."""
    exact, meshes, ranked, score = rec["exact"], rec["mesh_problems"], rec["ranked"], rec["score"]
    lines = ["## Across problems", ""]
    if not exact:
        return lines + ["No problem with an exact error was run: no recommendation.", ""]
    n, p, m = len(schemes), len(exact), len(meshes)
    broke = sorted(((s, b) for s, b in rec["breakdowns"].items() if b), key=lambda kv: -len(kv[1]))
    best = ranked[0] if ranked else None
    if best:
        ahead = ", ".join(f"{s} {score[s]:.3g} x" for s in ranked[1:3])
        wins = sum(rec["winners"].get(q) == best for q in exact)
        text = (f"**Recommendation: {best}**. {len(ranked)} of the {n} schemes converge as "
                f"required on the {_count(p, 'problem')} with an exact error"
                + (f" and break down on none of the real-world-like meshes ({m})" if m else "")
                + f"; of these, {best} has the smallest finest-level errors: {score[best]:.3g} x "
                f"the smallest of any scheme, geometric mean over those problems"
                + (f" (then {ahead})" if ahead else "") + f". It is the most accurate on "
                f"{wins} of them" + (
                    f"; the second table below lists the {_count(len(rec['exceptions']), 'problem')}"
                    " where another scheme is more accurate or it shows no order ~2."
                    if rec["exceptions"] else "."))
        if rec["tied"]:
            text += (f" {best} and {', '.join(rec['tied'])} are practically tied (scores "
                     f"within {100 * TIE:.0f} %): either is a sound choice.")
    else:
        text = (f"**No scheme wins everywhere**: none of the {n} schemes converges as required "
                "on every problem with an exact error without breaking down on a "
                "real-world-like mesh.")
    if m:
        text += (f" On the {_count(m, 'real-world-like mesh')} " + (
            f"{len(broke)} of the {n} schemes break down at least once (most often "
            f"{broke[0][0]}, on {len(broke[0][1])})." if broke else "no scheme breaks down."))
    lines += [text, "",
              f"Problems with an exact error: {', '.join(exact)}. Real-world-like meshes (a "
              f"breakdown disqualifies): {', '.join(meshes) or 'none run'}. Without an exact "
              f"value (breakdown times only): {', '.join(rec['singular']) or 'none'}.", ""]
    if rec["relaxed"]:
        lines += [f"No scheme reaches order ~2 on {', '.join(rec['relaxed'])}: there a scheme "
                  "only has to finish every level.", ""]
    standing = {s: "recommended" if s == best else "tied" if s in rec["tied"] else "candidate"
                for s in ranked}
    standing.update({s: "left out: " + "; ".join(r) for s, r in rec["why_not"].items()})
    order = ranked + sorted(rec["why_not"], key=lambda s: (not np.isfinite(score[s]), score[s]))
    lines += [markdown(Table(
        ["scheme", "finest error / smallest (geometric mean)",
         "breakdowns on real-world-like meshes", "verdict"],
        [(s, formatted(score[s], ".3g"), f"{len(rec['breakdowns'][s])} of {m}" if m else "–",
          standing[s]) for s in order], align="lrrl")), ""]
    if rec["exceptions"]:
        lines += [f"Where {best} is not the most accurate, or shows no order ~2:", "",
                  markdown(Table(
                      ["problem", f"EOC of {best}", "finest error / smallest",
                       "most accurate", "note"],
                      [(e["problem"], BELOW_ACCURACY if e["class"] == "below_accuracy"
                        else formatted(e["eoc"], ".2f"), formatted(e["ratio"], ".3g"),
                        e["winner"] or "none", e["note"] or "–") for e in rec["exceptions"]],
                      align="lrrll")),
                  ""]
    for q in rec["singular"]:
        cls = {s: rec["classes"].get((q, s), "missing") for s in schemes}
        done = [s for s in schemes if cls[s] not in ("broke_down", "missing")]
        times = {s: verdict[(q, s)]["t_failed"] for s in schemes if cls[s] == "broke_down"
                 and np.isfinite(verdict[(q, s)]["t_failed"])}
        text = f"On {q} " + (f"{', '.join(done)} finished every level" if done else
                             "every scheme broke down")
        if times:
            latest = max(times, key=times.get)
            text += ("; " if done else ", ") + f"the latest breakdown: {latest} at t = " \
                f"{times[latest]:.4g} (earliest: {min(times, key=times.get)} at t = " \
                f"{min(times.values()):.4g}; coarsest failing level)"
        lines.append(text + ".")
    return lines + [""]


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
                           scope=scope_lines(plan, list(SCHEMES), list(PROBLEMS), labels))
    write_text(out, text)
    return text
