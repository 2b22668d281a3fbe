"""The tables of the study beyond Table 3.1: the T monitor, stability, orders in time and space."""

import numpy as np
import pandas as pd

from mcfbench.geometry.exact import eoc
from mcfbench.presentation.formats import MISSING, fix, int_or, sci, sig, tex_inline
from mcfbench.presentation.tables import Table, csv, latex, markdown
from mcfbench.running.schemes import split_name
from mcfbench.studies.beyond.scaling import scaling_points, scaling_rows, scaling_table
from mcfbench.studies.convergence.tables import (
    eoc_column,
    l2_cell,
    label,
    LEVEL_COLUMNS,
    level_table,
    notes_latex,
    notes_markdown,
    record_rows,
)

MONITOR_COLUMNS = ["t_reached", "t_monitor_start", "t_monitor_end", "t_exit"]


BEYOND_LEVEL_COLUMNS = LEVEL_COLUMNS[:-1] + ["peak_rss_mb", "step_seconds", "memory_mb"] + \
    MONITOR_COLUMNS + ["message"]


STABILITY_COLUMNS = ["study", "scheme", "label", "level", "nT", "tau", "t_final", "N",
                     "status", "t_failed", "t_reached", "t_monitor_start",
                     "t_min_barycentric", "t_monitor_end", "t_exit", "l2_error",
                     "iterations", "wall_seconds", "message"]


SPACE_COLUMNS = ["scheme", "label", "level", "h", "nV", "nF", "nT", "tau", "t_final", "N",
                 "l2_error", "eoc", "iterations", "wall_seconds", "status", "t_failed",
                 "t_min_barycentric", "message"]


TIME_COLUMNS = ["scheme", "label", "level", "t_final", "reference_tau", "tau", "N", "error",
                "order", "volume_error", "volume_order", "l2_error", "status", "message"]


INTEGRATOR_COLUMNS = ["scheme", "label", "integrator", "level", "tau", "N", "l2_euler",
                      "l2_other", "l2_ratio", "cpu_euler", "cpu_other", "cost_ratio",
                      "l2_other_at_euler_cpu", "equal_cpu_ratio"]


SERIES_COLUMNS = ["study", "scheme", "label", "level", "tau", "t_final", "status", "n", "t",
                  "t_monitor"]


def monitor_summary(record):
    """What the T monitor of one run did.

    Returns
    -------
    dict
        ``t_reached`` (last time level computed: for a run stopped by an
        invalid state, e.g. ``t_escaped``, that state; after a solver failure
        the last state before it), ``t_monitor_start`` (at n = 0),
        ``t_monitor_end`` (at ``t_reached``), ``t_exit`` (first time a T-vertex
        was outside its triangle: the monitor < 0, or the breakdown when the
        status is ``t_escaped``; NaN if never). The monitor values are NaN for
        schemes without T-vertices.
    """
    series = record["series"]
    t = np.asarray(series["t"], dtype=float)
    monitor = np.asarray(series["t_min_barycentric"], dtype=float)
    outside = np.flatnonzero(monitor < 0)
    exit_time = t[outside[0]] if len(outside) else (
        record["t_failed"] if record["status"] == "t_escaped" else np.nan)
    return {"t_reached": float(t[-1]), "t_monitor_start": float(monitor[0]),
            "t_monitor_end": float(monitor[-1]), "t_exit": float(exit_time)}


def monitor_series(records, study):
    """The T monitor at every time level of the runs with T-vertices, long format."""
    frames = []
    for r in records:
        if r["nT"] == 0:
            continue
        monitor = np.asarray(r["series"]["t_min_barycentric"], dtype=float)
        frames.append(pd.DataFrame({
            "study": study, "scheme": r["scheme"], "label": label(r["scheme"]),
            "level": r["level"], "tau": r["tau"], "t_final": r["settings"]["t_final"],
            "status": r["status"], "n": np.arange(len(monitor)),
            "t": np.asarray(r["series"]["t"], dtype=float), "t_monitor": monitor}))
    return pd.concat(frames, ignore_index=True) if frames else \
        pd.DataFrame(columns=SERIES_COLUMNS)


def beyond_level_table(records, levels, paper_schemes):
    """:func:`level_table` of every scheme with the peak memory of each run, the
    columns of the scaling study (:func:`~mcfbench.studies.beyond.scaling.scaling_points`)
    and the T monitor (:func:`monitor_summary`); ``levels``: scheme -> its levels."""
    table = level_table(records, list(levels), levels, paper_schemes=set(paper_schemes))
    summary = pd.DataFrame([{"peak_rss_mb": records[s, lv]["peak_rss_mb"],
                             **monitor_summary(records[s, lv])}
                            for s, lv in zip(table["scheme"], table["level"])])
    return scaling_points(pd.concat([table, summary], axis=1))[BEYOND_LEVEL_COLUMNS]


def stability_table(level_records, long_records):
    """One row per run with T-vertices: the levels study, then the long runs."""
    rows = []
    for study, records in (("levels", level_records), ("long_time", long_records)):
        for r in records:
            if r["nT"] == 0:
                continue
            rows.append({**{k: v for k, v in r.items() if k in STABILITY_COLUMNS},
                         "study": study, "label": label(r["scheme"]),
                         "t_final": r["settings"]["t_final"], **monitor_summary(r)})
    return pd.DataFrame(rows, columns=STABILITY_COLUMNS)


def space_table(records, schemes, levels):
    """Order in space: one row per (scheme, level), EOC between finished runs."""
    parts = []
    for scheme in schemes:
        part = record_rows(records, [scheme], levels)
        part["eoc"] = eoc_column(part["level"], part["l2_error"], part["status"])
        parts.append(part)
    return pd.concat(parts, ignore_index=True)[SPACE_COLUMNS]


def time_order(taus, errors, status):
    """Order ``log(e_{j-1} / e_j) / log(tau_{j-1} / tau_j)`` between finished runs.

    (3.1) with tau for h; NaN for the first row and next to a run that broke
    down. For halved time steps it is the ``eoc`` of
    :func:`mcfbench.running.run.time_convergence`.
    """
    return eoc(errors, ok=np.asarray(status) == "ok", sizes=taus)


def time_table(records):
    """Order in time: one row per (scheme, tau); a failed reference is one row
    with status ``reference_failed``."""
    parts = []
    for r in records:
        base = {"scheme": r["scheme"], "label": label(r["scheme"]), "level": r["level"],
                "t_final": r["t_final"], "reference_tau": r["reference_tau"]}
        if r["outcome"] != "ok":
            parts.append(pd.DataFrame([{**base, "tau": np.nan, "N": np.nan, "error": np.nan,
                                        "order": np.nan, "volume_error": np.nan,
                                        "volume_order": np.nan, "l2_error": np.nan,
                                        "status": r["outcome"], "message": r["message"]}]))
            continue
        rows = pd.DataFrame(r["rows"])
        for column in ("tau", "error", "volume_error", "l2_error"):
            rows[column] = pd.to_numeric(rows[column], errors="coerce").astype(float)
        part = rows.assign(**base, message="")
        part["order"] = time_order(part["tau"], part["error"], part["status"])
        part["volume_order"] = time_order(part["tau"], part["volume_error"], part["status"])
        parts.append(part)
    table = pd.concat(parts, ignore_index=True)
    table["N"] = table["N"].astype("Int64")
    return table[TIME_COLUMNS]


def integrator_table(levels):
    """Each scheme of the levels table that also ran as ``NAME@INTEGRATOR`` against
    its Euler runs, per level (issue #22: the Table 3.1 setting with BDF2).

    Columns: the two L2 errors (3.2) and ``l2_ratio`` (other / Euler); the CPU
    seconds of the runs and ``cost_ratio``, the ratio of the CPU seconds per step
    (both run the same steps); ``l2_other_at_euler_cpu``, the other integrator's
    error at the Euler run's CPU time (log-log interpolation over the other
    integrator's finished levels, NaN outside them) and ``equal_cpu_ratio`` (it /
    the Euler error): the work-precision view.
    """
    rows = []
    done = levels[levels["status"] == "ok"]
    for name in dict.fromkeys(levels["scheme"]):
        base, integrator = split_name(name)
        if name == base or base not in set(levels["scheme"]):
            continue
        euler = done[done["scheme"] == base].set_index("level")
        other = done[done["scheme"] == name].set_index("level")
        curve = other.sort_values("cpu_seconds")
        for level in sorted(set(euler.index) & set(other.index)):
            e, o = euler.loc[level], other.loc[level]
            at_cpu = np.exp(np.interp(np.log(e.cpu_seconds), np.log(curve["cpu_seconds"]),
                                      np.log(curve["l2_error"]), left=np.nan, right=np.nan)) \
                if len(curve) > 1 and e.cpu_seconds > 0 else np.nan
            rows.append({"scheme": base, "label": label(base), "integrator": integrator,
                         "level": level, "tau": e.tau, "N": e.N, "l2_euler": e.l2_error,
                         "l2_other": o.l2_error, "l2_ratio": o.l2_error / e.l2_error,
                         "cpu_euler": e.cpu_seconds, "cpu_other": o.cpu_seconds,
                         "cost_ratio": (o.cpu_seconds / o.N) / (e.cpu_seconds / e.N),
                         "l2_other_at_euler_cpu": at_cpu,
                         "equal_cpu_ratio": at_cpu / e.l2_error})
    return pd.DataFrame(rows, columns=INTEGRATOR_COLUMNS)


def integrator_rows(table):
    header = ["scheme", "integrator", "level", "tau", "L2 Euler", "L2 other", "ratio",
              "CPU s Euler", "CPU s other", "cost/step ratio", "other at Euler's CPU",
              "ratio at equal CPU"]
    rows = [[r.label, r.integrator, str(r.level), sig(r.tau, 4), sci(r.l2_euler, 3),
             sci(r.l2_other, 3), fix(r.l2_ratio, 3), sig(r.cpu_euler, 3), sig(r.cpu_other, 3),
             fix(r.cost_ratio, 2), sci(r.l2_other_at_euler_cpu, 3), fix(r.equal_cpu_ratio, 3)]
            for r in table.itertuples()]
    return header, rows


def beyond_tables(inputs, records, beyond, paper_schemes):
    """Every table of the beyond study from checked records.

    Parameters
    ----------
    inputs : dict
        Study (``levels``, ``long_time``, ``space``, ``time``) -> the keys of its records.
    records : dict
        Key -> record (a time study's: :func:`mcfbench.studies.beyond.aggregate.time_records`).
    beyond : dict
        The normalised config key ``beyond`` (:func:`mcfbench.studies.beyond.plan`).
    paper_schemes : list of str
        Schemes compared with the published values.

    Returns
    -------
    tables : dict
        ``levels``, ``stability``, ``time_convergence``, ``space_convergence``,
        ``integrators`` (:func:`integrator_table`).
    series : pandas.DataFrame
        The T monitor of the levels and long runs (:func:`monitor_series`).
    """
    by_level = {(records[p]["scheme"], records[p]["level"]): records[p]
                for p in inputs["levels"]}
    # the levels each scheme ran: beyond.levels, and beyond.finest.level for some
    runs = {s: sorted(lv for scheme, lv in by_level if scheme == s) for s in beyond["schemes"]}
    levels = [by_level[s, lv] for s, scheme_levels in runs.items() for lv in scheme_levels]
    long = [records[p] for p in inputs["long_time"]]
    space = {(records[p]["scheme"], records[p]["level"]): records[p] for p in inputs["space"]}
    tables = {
        "levels": beyond_level_table(by_level, runs, paper_schemes),
        "stability": stability_table(levels, long),
        "time_convergence": time_table([records[p] for p in inputs["time"]]),
        "space_convergence": space_table(space, beyond["space_study"]["schemes"],
                                         beyond["space_study"]["levels"]),
    }
    tables["integrators"] = integrator_table(tables["levels"])
    series = pd.concat([monitor_series(levels, "levels"), monitor_series(long, "long_time")],
                       ignore_index=True)
    return tables, series


def beyond_levels_rows(table, schemes, paper_schemes):
    """L2 and EOC per level, the schemes side by side, the paper first."""
    header = ["level", "h", "tau", "N", "L2 paper", "EOC paper"]
    for s in schemes:
        header += [f"{label(s)} L2", f"{label(s)} EOC"] + \
            ([f"{label(s)}/paper"] if s in paper_schemes else [])
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = table[table["level"] == level].iloc[0]
        paper = table[(table["level"] == level) & table["paper_l2_error"].notna()]
        row = [str(level), f"{first.h:.4f}", f"{first.tau:g}", str(first.N),
               sci(paper["paper_l2_error"].iloc[0], 2) if len(paper) else MISSING,
               fix(paper["paper_eoc"].iloc[0], 2) if len(paper) else MISSING]
        for s in schemes:
            width = 3 if s in paper_schemes else 2
            if (s, level) not in by.index:          # a level this scheme did not run
                row += [MISSING] * width
                continue
            r = by.loc[(s, level)]
            row += [l2_cell(r, 4), fix(r.eoc, 3), fix(r.l2_ratio, 3)][:width]
        rows.append(row)
    return header, rows


def cost_rows(table, schemes):
    """Iterations, CPU and wall seconds and peak memory per level and scheme."""
    header = ["level", "N"]
    for s in schemes:
        header += [f"{label(s)} iter", f"{label(s)} CPU s", f"{label(s)} wall s",
                   f"{label(s)} peak MB"]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        row = [str(level), str(table[table["level"] == level].iloc[0].N)]
        for s in schemes:
            if (s, level) not in by.index:
                row += [MISSING] * 4
                continue
            r = by.loc[(s, level)]
            row += [str(r.iterations), sig(r.cpu_seconds, 3), sig(r.wall_seconds, 3),
                    int_or(r.peak_rss_mb)]
        rows.append(row)
    return header, rows


def breakdown_notes(table):
    """One sentence per run that broke down (a table with the monitor columns)."""
    lines = []
    for r in table[table["status"] != "ok"].itertuples():
        study = f" ({r.study})" if "study" in table.columns else ""
        text = (f"{label(r.scheme)} level {r.level}{study}: {r.status} at "
                f"t = {r.t_failed:.4g} (step {round(r.t_failed / r.tau)} of {r.N})")
        if np.isfinite(r.t_monitor_end):
            text += f"; T monitor {r.t_monitor_end:.3g} at t = {r.t_reached:.4g}"
            if np.isfinite(r.t_exit):
                text += f", a T-vertex outside its triangle from t = {r.t_exit:.4g}"
        lines.append(text + f". {r.message}")
    return lines


def stability_rows(table):
    header = ["study", "scheme", "level", "t_f", "N", "status", "t_failed",
              "T monitor n=0", "min T monitor", "T monitor at end", "T outside from t",
              "L2", "wall s"]
    rows = [[r.study, label(r.scheme), str(r.level), f"{r.t_final:g}", str(r.N), r.status,
             sig(r.t_failed, 4), fix(r.t_monitor_start, 3), sig(r.t_min_barycentric, 3),
             sig(r.t_monitor_end, 3), sig(r.t_exit, 4), sci(r.l2_error, 4),
             sig(r.wall_seconds, 3)] for r in table.itertuples()]
    return header, rows


def time_rows(table):
    header = ["scheme", "tau", "N", "error at t_f", "order", "volume error", "order (volume)",
              "L2 (3.2)", "status"]
    rows = [[label(r.scheme), sig(r.tau, 4), int_or(r.N), sci(r.error, 3), fix(r.order, 3),
             sci(r.volume_error, 3), fix(r.volume_order, 3), sci(r.l2_error, 3), r.status]
            for r in table.itertuples()]
    return header, rows


def order_rows(table):
    """The time table as scheme x integrator: the median order (pointwise and by
    volume) over the pairs of halved steps, one row per scheme, one column pair per
    integrator (``NAME@INTEGRATOR`` rows; Euler without ``@``)."""
    done = table[table["status"] == "ok"]
    parts = [split_name(name) for name in done["scheme"]]
    done = done.assign(base=[base for base, _ in parts],
                       integrator=[integrator for _, integrator in parts])
    integrators = list(dict.fromkeys(done["integrator"]))
    medians = done.groupby(["base", "integrator"], sort=False)[["order", "volume_order"]] \
        .median()
    header = ["scheme"] + [f"{i} {kind}" for i in integrators
                           for kind in ("order", "order (volume)")]
    rows = []
    for base in dict.fromkeys(done["base"]):
        row = [label(base)]
        for integrator in integrators:
            if (base, integrator) in medians.index:
                r = medians.loc[(base, integrator)]
                row += [fix(r["order"], 2), fix(r["volume_order"], 2)]
            else:
                row += [MISSING, MISSING]
        rows.append(row)
    return header, rows


def space_rows(table, schemes):
    header = ["level", "h", "N"]
    for s in schemes:
        header += [f"{label(s)} n_V", f"{label(s)} L2", f"{label(s)} EOC"]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = by.loc[(schemes[0], level)]
        row = [str(level), f"{first.h:.4f}", str(first.N)]
        for s in schemes:
            r = by.loc[(s, level)]
            row += [str(r.nV), l2_cell(r, 4), fix(r.eoc, 3)]
        rows.append(row)
    return header, rows


def _beyond_descriptions(beyond, settings):
    time, space, long = beyond["time_study"], beyond["space_study"], beyond["long_time"]
    finest = beyond["finest"]
    return {
        "levels": (
            f"Shrinking unit sphere (Section 3.1), t_f = {settings['t_final']:g}, "
            f"tau = {settings['tau_level_1']:g} / 4^(level-1) (tau ~ h^2), BiCGStab rtol = "
            f"{settings['rtol']:g}. L2: space-time error (3.2) (vertex schemes: over the "
            "vertices, lumped-mass weights); EOC (3.1) against the next coarser level, only "
            "between runs that finished; /paper: ours over the published L2 of Table 3.1 "
            "(levels 1-5). A run that broke down shows `failed (t = time of the breakdown)`."
            + (f" Level {finest['level']} ran for "
               f"{', '.join(label(s) for s in finest['schemes'])} only (`beyond.finest`), "
               f"at BiCGStab rtol = {finest['rtol']:g} (`beyond.finest.rtol`)."
               if finest["schemes"] else "")
            + " peak MB: peak resident memory of the run's job (ru_maxrss)."),
        "stability": (
            "T monitor: smallest barycentric coordinate of any T-vertex projected into "
            "its triangle (1/3 at the barycentre; below 0 a T-vertex is outside, and the "
            "run stops with status `t_escaped`). `levels`: the runs of the L2 table (t_f as "
            f"there); `long_time`: level {long['level']} continued to t_f = "
            f"{long['t_final']:g}. 'T monitor at end': at the last time level computed (for a "
            "run stopped by an invalid state, that state; after a solver failure, the last "
            "state before it); 'T outside from t': first time a T-vertex was outside its "
            "triangle."),
        "time_convergence": (
            f"Icosphere level {time['level']} (fixed mesh), t_f = {time['t_final']:g}, "
            f"tau = {', '.join(f'{t:g}' for t in time['taus'])}. error: distance at t_f to "
            f"a reference with tau = {time['taus'][-1] / time['reference_factor']:g} on "
            "the same mesh, weighted by the scheme's quadrature weights (DDFV: the "
            "covolumes chi / 2 over F- and T-vertices; mcfbench.running.run.time_convergence); "
            "order: log(e_prev / e) / log(tau_prev / tau); volume error: |vol - vol_ref|, "
            "the volume between the two surfaces, blind to tangential motion (BGN moves its "
            "points tangentially anew at every step, so only this error measures its time "
            "error); L2 (3.2): against the exact sphere (space + time error). NAME, BDF2: "
            "the scheme stepped by linearly implicit BDF2 (mcfbench.running.integrators)."),
        "integrators": (
            "The runs of the L2 table (the Table 3.1 setting) of every scheme that also ran "
            "with another integrator (NAME@INTEGRATOR in `beyond.schemes`), level by level "
            "against its Euler runs: the L2 errors (3.2) and their ratio, the CPU seconds "
            "of each run (flow construction, steps, error; one core) and the ratio of the "
            "CPU seconds per step, and the other integrator's L2 error at the Euler run's "
            "CPU time (log-log interpolation between its levels; -- outside them) over "
            "the Euler error: what the integrator buys at equal cost. Both integrators on "
            "the same footing: same scheme, solver, rtol, machine and one core per job; "
            "CPU seconds of jobs that ran side by side on a shared machine."),
        "space_convergence": (
            f"tau = {space['tau']:g} on every level, t_f = {space['t_final']:g}: the "
            "error (3.2) against the exact sphere with the time error made small; EOC "
            "(3.1) between consecutive levels."),
    }


def _markdown(title, description, tables, notes=()):
    parts = [f"# {title}", "", description, ""]
    for heading, (header, rows) in tables:
        parts += ([f"## {heading}", ""] if heading else []) + [markdown(Table(header, rows)),
                                                                 ""]
    return "\n".join(parts + notes_markdown(notes))


def _latex(description, tables, notes=()):
    parts = ["% generated by mcfbench.studies.beyond.tables.beyond_documents; needs booktabs, graphicx"]
    for caption, tab_label, (header, rows) in tables:
        parts += [latex(Table(header, rows, caption=f"{caption} {description}",
                              label=tab_label), text=tex_inline), ""]
    return "\n".join(parts + notes_latex(notes)) + "\n"


def beyond_documents(tables, beyond, settings, paper_schemes):
    """``name -> {"csv": text, "md": text, "tex": text}`` of the beyond tables
    (:func:`beyond_tables`); ``settings`` holds ``t_final``, ``tau_level_1``, ``rtol``."""
    schemes = beyond["schemes"]
    levels, stability = tables["levels"], tables["stability"]
    time, space = tables["time_convergence"], tables["space_convergence"]
    space_schemes = list(dict.fromkeys(space["scheme"]))
    time_labels = ", ".join(label(s) for s in dict.fromkeys(time["scheme"]))
    notes = {
        "levels": breakdown_notes(levels), "stability": breakdown_notes(stability),
        "space_convergence": [f"{label(r.scheme)} level {r.level}: {r.status} at "
                              f"t = {r.t_failed:.4g}. {r.message}"
                              for r in space[space["status"] != "ok"].itertuples()],
        "time_convergence": [f"{label(r.scheme)}: {r.status}. {r.message}"
                             for r in time[time["status"] != "ok"].itertuples()]}
    desc = _beyond_descriptions(beyond, settings)
    level_rows = beyond_levels_rows(levels, schemes, paper_schemes)
    md = {
        "levels": _markdown("Beyond Table 3.1: L2 error and EOC per level and scheme",
                            desc["levels"], [
                                ("L2 error and EOC", level_rows),
                                ("Cost: BiCGStab iterations, CPU and wall seconds of the flow "
                                 "(one core; wall seconds depend on the other jobs running), "
                                 "peak memory of the job",
                                 cost_rows(levels, schemes))], notes["levels"]),
        "stability": _markdown("T-vertex stability: the T monitor of every run",
                               desc["stability"], [("", stability_rows(stability))],
                               notes["stability"]),
        "time_convergence": _markdown("Convergence in time (fixed mesh)",
                                      desc["time_convergence"], [
                                          ("Median order by scheme and integrator",
                                           order_rows(time)),
                                          ("Every run", time_rows(time))],
                                      notes["time_convergence"]),
        "space_convergence": _markdown("Convergence in space (fixed time step)",
                                       desc["space_convergence"],
                                       [("", space_rows(space, space_schemes))],
                                       notes["space_convergence"]),
        "integrators": _markdown("Second order in time: each integrator against Euler on "
                                 "the Table 3.1 setting", desc["integrators"],
                                 [("", integrator_rows(tables["integrators"]))]),
    }
    tex = {
        "levels": _latex(desc["levels"], [
            ("L2 error and EOC per level and scheme.", "tab:beyond-levels", level_rows),
            ("Cost: BiCGStab iterations, CPU and wall seconds (one core), peak memory.",
             "tab:beyond-cost",
             cost_rows(levels, schemes))], notes["levels"]),
        "stability": _latex(desc["stability"], [("T-vertex stability.", "tab:beyond-stability",
                                                 stability_rows(stability))],
                            notes["stability"]),
        "time_convergence": _latex(desc["time_convergence"], [
            ("Median order in time by scheme and integrator.", "tab:beyond-time-orders",
             order_rows(time)),
            (f"Convergence in time ({time_labels}).", "tab:beyond-time", time_rows(time))],
            notes["time_convergence"]),
        "space_convergence": _latex(desc["space_convergence"], [
            ("Convergence in space.", "tab:beyond-space", space_rows(space, space_schemes))],
            notes["space_convergence"]),
        "integrators": _latex(desc["integrators"], [
            ("Integrators against Euler on the Table 3.1 setting.", "tab:beyond-integrators",
             integrator_rows(tables["integrators"]))]),
    }
    return {name: {"csv": csv(table), "md": md[name], "tex": tex[name]}
            for name, table in tables.items()}


def scaling_tables(records, levels, fit_levels):
    """The scaling study from its checked records (its own runs in the run store).

    Parameters
    ----------
    records : dict
        Key -> record of the runs of the study.
    levels, fit_levels : dict
        Scheme -> its levels, its levels of the fits, in row order
        (:func:`mcfbench.studies.beyond.plan.scaling_levels`, ``scaling_fit_levels``).

    Returns
    -------
    points : pandas.DataFrame
        One row per run (:func:`beyond_level_table`: unknowns ``nV``,
        ``step_seconds``, ``peak_rss_mb``, ``memory_mb``, ...).
    table : pandas.DataFrame
        :func:`~mcfbench.studies.beyond.scaling.scaling_table` of ``points``.
    """
    by_level = {(r["scheme"], r["level"]): r for r in records.values()}
    runs = {s: [lv for lv in scheme_levels if (s, lv) in by_level]
            for s, scheme_levels in levels.items()}
    points = beyond_level_table(by_level, runs, paper_schemes=())
    return points, scaling_table(points, fit_levels)


def scaling_documents(table, beyond, settings):
    """``{"csv": text, "md": text, "tex": text}`` of the scaling table
    (:func:`scaling_tables`); ``settings`` holds ``t_final``."""
    scaling = beyond["scaling"]
    description = (
        f"Cost against size: {len(scaling['schemes'])} schemes (`beyond.scaling.schemes`) "
        f"on levels {', '.join(str(lv) for lv in scaling['levels'])}, one job (one fresh "
        "process) each, shared with the L2 table where both run it; "
        "unknowns n: F- plus T-vertices for DDFV, the mesh vertices otherwise. CPU "
        "s/step: the run's CPU seconds (flow construction, steps, error) over its steps; "
        "peak MB: the job's peak resident memory (ru_maxrss), and above that of the "
        "scheme's coarsest run (imports, compiled kernels, warm-up: what every job "
        "takes on). Slopes: p of c n^p, least squares in log-log over the finished "
        f"runs of levels {', '.join(str(lv) for lv in scaling['fit_levels'])} "
        "(`beyond.scaling.fit_levels`)"
        + "".join(f"; {label(s)} up to level {lv}, fitted on its "
                  f"{len(scaling['fit_levels'])} finest levels"
                  for s, lv in scaling["up_to"].items())
        + (" (`beyond.scaling.up_to`: a finer run costs too much)" if scaling["up_to"] else "")
        + "; a slope of 1 is cost linear in the unknowns. "
        "The timings are on the same footing: same machine, one thread per job "
        f"(`threads`), same problem (the shrinking sphere, tau ~ h^2, t_f = "
        f"{settings['t_final']:g}), warm-up (compilation, cache loading, first calls) "
        "done before the clock starts; CPU seconds of jobs that ran side by side on a "
        "shared machine.")
    rows = scaling_rows(table)
    return {"csv": csv(table),
            "md": _markdown("Cost against size: CPU time per step and peak memory against "
                            "the unknowns, fitted slopes", description, [("", rows)]),
            "tex": _latex(description, [("CPU time per step and peak memory against the "
                                         "unknowns.", "tab:beyond-scaling", rows)])}
