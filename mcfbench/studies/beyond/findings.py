"""The findings of the beyond study: the verdicts from its tables only (:func:`findings`:
which schemes stayed stable, the finest common level, the ranking) and their words
(:func:`beyond_findings`, written by :func:`write_findings`): every number is read
from the tables."""

import numpy as np

from mcfbench.presentation.formats import (
    pct,
    sci,
)
from mcfbench.studies.convergence.tables import label


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
    lines = ["## Which schemes stay stable", ""]
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
    return lines + [""]


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


def finest_section(levels, schemes, finest):
    """Level ``finest`` (the finest every scheme ran), beyond the paper, and the finer
    levels some schemes ran (``beyond.finest``): errors, orders and cost."""
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
    return lines + [""]


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


def integrator_section(verdict):
    """What a second-order integrator buys, in words: ``verdict["time_orders"]`` and
    ``verdict["integrators"]`` of :func:`mcfbench.studies.beyond.findings`."""
    lines = ["## Second order in time", ""]
    for integrator, (order, rows) in verdict["time_orders"].items():
        point = [r for r in rows if r["pointwise"]]
        volume_only = [r for r in rows if not r["pointwise"] and r["by_volume"]]
        neither = [r for r in rows if not r["pointwise"] and not r["by_volume"]]
        text = (f"- **{integrator}** (order {order}): pointwise order "
                f"{min(r['order'] for r in point):.2f}-{max(r['order'] for r in point):.2f} "
                f"for {len(point)} of {len(rows)} schemes" if point else
                f"- **{integrator}** (order {order}): no scheme has it pointwise")
        if volume_only:
            text += "; by the volume between the surfaces only: " + ", ".join(
                f"{label(r['scheme'])} ({r['volume_order']:.2f}; pointwise {r['order']:.2f})"
                for r in volume_only)
        if neither:
            text += "; neither: " + ", ".join(
                f"{label(r['scheme'])} (pointwise {r['order']:.2f}, volume "
                f"{r['volume_order']:.2f})" for r in neither)
        lines.append(text + ".")
    if verdict["time_orders"]:
        lines.append("(Median over the pairs of halved time steps of the time table.)")
        lines.append("")
    if verdict["integrators"]:
        lines.append("On the Table 3.1 setting (tau ~ h^2), finest level both ran: " + "; ".join(
            f"{r['label']} with {r['integrator']} (level {r['level']}): L2 "
            f"{r['l2_ratio']:.2f} x Euler's at {r['cost_ratio']:.2f} x the CPU per step"
            + (f", {r['equal_cpu_ratio']:.2f} x Euler's at equal CPU time"
               if np.isfinite(r["equal_cpu_ratio"]) else "")
            for r in verdict["integrators"]) + ".")
        lines.append("")
    return lines


def summary(verdict):
    """The verdict (:func:`mcfbench.studies.beyond.findings`) in two sentences."""
    if not verdict["variants"]:
        return ["## Summary", "", "No DDFV scheme finished every run.", ""]
    text = (f"Stable (every run finished, no T-vertex left its triangle): "
            f"{'; '.join(map(label, verdict['variants']))}; not stable: "
            f"{'; '.join(map(label, verdict['unstable'])) or 'none'}.")
    if verdict["ranking"]:
        (best, error), *rest = verdict["ranking"]
        text += f" On level {verdict['finest']} the most accurate stable variant is " \
                f"{label(best)} (L2 {sci(error, 4)}"
        others = [f"{label(scheme)} {value / error:.2f} x that" for scheme, value in rest]
        text += ("; " + ", ".join(others) if others else "") + ")."
    if verdict["deviations"]:
        text += " Largest deviation from the published errors (levels of Table 3.1): " + \
            "; ".join(f"{label(scheme)} {pct(ratio - 1, 1)} (level {level})"
                      for scheme, level, ratio in verdict["deviations"]) + "."
    return ["## Summary", "", text, ""]


def beyond_findings(levels, stability, time, space, schemes, paper_schemes, t_final, tau_1,
                    verdict):
    """The findings of the beyond study (Markdown) from its tables (DataFrames of
    :func:`mcfbench.studies.beyond.tables.beyond_tables`) and its ``verdict``
    (:func:`mcfbench.studies.beyond.findings`); ``schemes``: those of the level table,
    ``paper_schemes``: those compared with the published values."""
    parts = ["# Beyond Table 3.1: findings", "",
             "Generated by `mcfbench.studies.beyond.findings.beyond_findings` from the tables in "
             "`results/beyond/tables/` (every number below is read from them). Shrinking "
             f"unit sphere, t_f = {t_final:g} unless stated, tau = {tau_1:g} / 4^(level-1).",
             ""]
    finest = verdict["finest"]
    parts += summary(verdict)
    parts += stability_section(levels, stability, schemes, t_final)
    parts += accuracy_section(levels, paper_schemes) + finest_section(levels, schemes, finest)
    parts += cost_section(levels, schemes, verdict["reference"], finest)
    parts += order_section(levels, time, space, paper_schemes)
    parts += integrator_section(verdict)
    parts += ["## Figures and tables", "",
              "![L2 error per level](figures/levels.png)", "",
              "![T monitor against time](figures/t_monitor.png)", "",
              "![Convergence in time](figures/time_convergence.png)", "",
              "![Convergence in space](figures/space_convergence.png)", "",
              "Tables: [levels](tables/levels.md), [stability](tables/stability.md), "
              "[time](tables/time_convergence.md), [space](tables/space_convergence.md), "
              "[integrators](tables/integrators.md) (CSV and LaTeX next to them).", ""]
    return "\n".join(parts)


ORDER_TOLERANCE = 0.3
"""A measured order in time within this of an integrator's order counts as that order."""


def findings(levels, stability, schemes, paper, time=None, integrators=None):
    """The verdicts of the study, from its tables only.

    Parameters
    ----------
    levels, stability : pandas.DataFrame
        The level and stability tables (:func:`aggregate`).
    time, integrators : pandas.DataFrame, optional
        The time table and the integrator table
        (:func:`mcfbench.studies.beyond.tables.integrator_table`).
    schemes : list
        The schemes of the level table (``beyond.schemes``).
    paper : list
        The schemes compared with the published Table 3.1 (:func:`paper_schemes`).

    Returns
    -------
    dict
        ``stable``: the schemes whose every run finished with no T-vertex outside
        its triangle (their runs of the stability table; of the level table for a
        scheme without T-vertices); ``variants`` and ``unstable``: the schemes of
        ``paper`` that are and are not stable; ``finest``: the finest level every
        scheme ran; ``reference``: the scheme the costs are compared with (the
        first of ``paper``, else of ``schemes``); ``ranking``: ``(scheme, L2
        error)`` of the stable ``variants`` that finished level ``finest``, most
        accurate first; ``deviations``: ``(scheme, level, L2 / published)`` of
        each stable variant's largest deviation from the published errors;
        ``time_orders``: integrator -> ``(its order, rows)``, a row per scheme of
        the time table with that integrator: ``scheme`` (without ``@``),
        ``order`` and ``volume_order`` (medians over the pairs of halved
        steps), ``pointwise`` and ``by_volume`` (within :data:`ORDER_TOLERANCE`
        of the integrator's order); ``integrators``: the rows of the integrator
        table at the finest level each (scheme, integrator) ran, as dicts.
    """
    import numpy as np

    stable = []
    for scheme in schemes:
        runs = stability[stability["scheme"] == scheme]
        if len(runs):
            outside = np.isfinite(runs["t_exit"]).any()
        else:                                   # no T-vertices: the level table's runs
            runs, outside = levels[levels["scheme"] == scheme], False
        if (runs["status"] == "ok").all() and not outside:
            stable.append(scheme)
    variants = [s for s in paper if s in stable]
    finest = int(levels.groupby("scheme")["level"].max()[schemes].min())
    rows = levels[(levels["level"] == finest) & levels["scheme"].isin(variants)]
    rows = rows[rows["status"] == "ok"].sort_values("l2_error")
    published = levels[levels["scheme"].isin(variants) & np.isfinite(levels["l2_ratio"])]
    worst = published.loc[(published["l2_ratio"] - 1).abs().groupby(published["scheme"]).idxmax()] \
        if len(published) else published
    return {"stable": stable, "variants": variants,
            "unstable": [s for s in paper if s not in stable], "finest": finest,
            "reference": paper[0] if paper else schemes[0],
            "ranking": [(r.scheme, float(r.l2_error)) for r in rows.itertuples()],
            "deviations": [(r.scheme, int(r.level), float(r.l2_ratio))
                           for r in worst.itertuples()],
            "time_orders": _time_orders(time), "integrators": _finest_comparisons(integrators)}


def _time_orders(time):
    """``time_orders`` of :func:`findings`."""
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import split_name

    verdict = {}
    if time is None:
        return verdict
    for scheme, part in time[time["status"] == "ok"].groupby("scheme", sort=False):
        base, name = split_name(scheme)
        order = INTEGRATORS[name].order
        point, volume = float(part["order"].median()), float(part["volume_order"].median())
        verdict.setdefault(name, (order, []))[1].append(
            {"scheme": base, "order": point, "volume_order": volume,
             "pointwise": abs(point - order) <= ORDER_TOLERANCE,
             "by_volume": abs(volume - order) <= ORDER_TOLERANCE})
    return verdict


def _finest_comparisons(integrators):
    """``integrators`` of :func:`findings`."""
    if integrators is None or not len(integrators):
        return []
    finest = integrators.loc[integrators.groupby(["scheme", "integrator"])["level"].idxmax()]
    return finest.to_dict("records")


def write_findings(tables, plan, paper, settings, out, log):
    """``findings.md`` from the tables only (``tables``: ``levels``, ``stability``,
    ``time``, ``space``, ``integrators`` -> CSV path; ``settings``: ``t_final``, ``tau_level_1``): the
    verdicts of :func:`findings` worded by
    :func:`mcfbench.studies.beyond.findings.beyond_findings`."""
    import pandas as pd

    from mcfbench.storage.atomic import write_files

    levels, stability, time_table, space, integrators = (
        pd.read_csv(tables[key]) for key in ("levels", "stability", "time", "space",
                                             "integrators"))
    schemes, paper = list(plan["schemes"]), list(paper)
    text = beyond_findings(levels, stability, time_table, space, schemes, paper,
                           float(settings["t_final"]), float(settings["tau_level_1"]),
                           findings(levels, stability, schemes, paper, time_table,
                                    integrators))
    write_files({str(out): text})
    log.info("wrote %s", out)
    return text
