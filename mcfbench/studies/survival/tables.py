"""The survival study's tables: one row per run (:func:`runs_table`) and one row per
scheme (:func:`survival_table`): the share of the meshes with and without thin
features it took to the end, and when the first defect came."""

import numpy as np

from mcfbench.presentation.formats import formatted
from mcfbench.presentation.tables import Table, markdown
from mcfbench.storage.statuses import reached

RUN_COLUMNS = ["mesh", "kind", "thin_features", "scheme", "status", "steps_done", "steps",
               "reached", "through", "removed_area_share", "rollbacks", "t_failed", "t_end",
               "defect_fraction", "min_angle", "cpu_seconds", "message"]
"""The columns of :func:`runs_table`."""

SUMMARY_COLUMNS = ["scheme", "meshes", "reached", "share", "plain_meshes", "plain_reached",
                   "plain_share", "thin_meshes", "thin_reached", "thin_share", "thin_through",
                   "rollbacks", "rolled_back_runs", "defect_fraction_q1",
                   "defect_fraction_median", "defect_fraction_q3"]
"""The columns of :func:`survival_table`: ``plain`` the meshes without thin features."""


def runs_table(records, meshes):
    """One row per run.

    Parameters
    ----------
    records : list of (str, dict)
        ``(mesh name, run record)`` (:mod:`mcfbench.storage.records`).
    meshes : dict
        The plan's ``meshes`` (name -> ``thin_features``, ``kind``).

    Returns
    -------
    pandas.DataFrame
        :data:`RUN_COLUMNS`: ``reached`` when the run ended ``ok`` after every step or
        ``extinct`` (the flow's end), its invariants holding at every step (the driver
        checks them; any other status names what broke) and its continuations
        (``NAME+surgery``) removing at most
        :data:`mcfbench.running.continuation.MAX_REMOVED_SHARE` of the area;
        ``through`` when it ended so after a continuation removed some area, whatever
        the share (``removed_area_share``, the record's); ``rollbacks`` the steps that
        folded and were rolled back (the record's, 0 in a record written before it);
        ``defect_fraction`` the time of its first defect over the run's final time
        (NaN when it reached the end).
    """
    import pandas as pd

    rows = []
    for mesh, r in records:
        steps, done = int(r["N"]), int(r["steps_done"])
        ended = reached(r["status"]) and (done == steps or r["status"] != "ok")
        removed = float(r.get("removed_area_share", 0.0))
        end = ended and not r.get("surgery_exceeded", False)
        t_end = steps * float(r["tau"])
        rows.append({"mesh": mesh, "kind": meshes[mesh]["kind"],
                     "thin_features": bool(meshes[mesh]["thin_features"]),
                     "scheme": r["scheme"], "status": r["status"], "steps_done": done,
                     "steps": steps, "reached": bool(end),
                     "through": bool(ended and removed > 0),
                     "removed_area_share": removed,
                     "rollbacks": int(r.get("rollbacks", 0)), "t_failed": r["t_failed"],
                     "t_end": t_end,
                     "defect_fraction": np.nan if end else float(r["t_failed"]) / t_end,
                     "min_angle": r["min_angle"], "cpu_seconds": r["cpu_seconds"],
                     "message": r["message"]})
    return pd.DataFrame(rows, columns=RUN_COLUMNS)


def survival_table(runs, schemes):
    """One row per scheme of ``schemes`` (in that order) from :func:`runs_table`.

    Returns
    -------
    pandas.DataFrame
        :data:`SUMMARY_COLUMNS`: the meshes run and reached, over all, without thin
        features (``plain``) and with them (``thin``), the shares (NaN without such
        meshes), ``thin_through`` the meshes with thin features whose run ended after a
        continuation removed some area (counted as reached or not), ``rollbacks`` the
        steps rolled back in all its runs and ``rolled_back_runs`` the runs with one or
        more, and the quartiles of the first defect's time over the final time among
        the runs that did not reach the end.
    """
    import pandas as pd

    def share(part):
        return (len(part), int(part["reached"].sum()),
                part["reached"].mean() if len(part) else np.nan)

    rows = []
    for scheme in schemes:
        own = runs[runs["scheme"] == scheme]
        failed = own.loc[~own["reached"], "defect_fraction"].to_numpy(dtype=float)
        q1, median, q3 = np.nanpercentile(failed, [25, 50, 75]) if np.isfinite(failed).any() \
            else (np.nan,) * 3
        rows.append(dict(zip(SUMMARY_COLUMNS, (
            scheme, *share(own), *share(own[~own["thin_features"]]),
            *share(own[own["thin_features"]]),
            int((own["through"] & own["thin_features"]).sum()), int(own["rollbacks"].sum()),
            int((own["rollbacks"] > 0).sum()), q1, median, q3))))
    return pd.DataFrame(rows, columns=SUMMARY_COLUMNS)


def survival_markdown(summary, plan):
    """The scheme table as Markdown with the settings in its notes."""
    import pandas as pd

    def count(k, n, p):
        return f"{k}/{n} ({formatted(100 * p, '.0f')} %)" if n else "–"

    view = pd.DataFrame({
        "scheme": summary["scheme"],
        "without thin features": [count(*v) for v in zip(
            summary["plain_reached"], summary["plain_meshes"], summary["plain_share"])],
        "with thin features": [count(*v) for v in zip(
            summary["thin_reached"], summary["thin_meshes"], summary["thin_share"])],
        "all": [count(*v) for v in zip(summary["reached"], summary["meshes"], summary["share"])],
        "rollbacks (runs)": [f"{k} ({n})" for k, n in zip(summary["rollbacks"],
                                                          summary["rolled_back_runs"])],
        "first defect (t / t_end: q1, median, q3)": [
            ", ".join(formatted(v, ".2f") for v in q) if np.isfinite(q[1]) else "–"
            for q in zip(summary["defect_fraction_q1"], summary["defect_fraction_median"],
                         summary["defect_fraction_q3"])]})
    notes = [f"Every scheme on every raw mesh that the intake reads "
             f"({len(plan['meshes'])}; refused with a named defect: "
             f"{len(plan['refused'])}), {plan['steps']} steps of tau = C (mean edge "
             f"length)^2, C = {plan['C']:g}, solver {plan['solver']} (rtol "
             f"{plan['rtol']:g}). Reached: every step done, or the flow's extinction, the "
             "invariants (the area never grows, no fold) holding at every step. Thin "
             "features: the corpus manifest's verdict (share of area thinner than 2 h "
             "above 2 %), decided before any run. Rollbacks: the steps that folded and "
             "were rolled back, the state before them remeshed (NAME+remesh, NAME+surgery), "
             "over all the scheme's runs, and (in brackets) its runs with one or more."]
    paired = paired_markdown(summary, plan.get("strategies", []))
    return (f"# Survival on raw meshes\n\n{markdown(Table.of_frame(view, notes=notes))}\n"
            + (f"\n## Every scheme beside its variants\n\n{paired}\n" if paired else ""))


def paired_rows(summary, strategies):
    """``[(scheme, {strategy or "none": row of summary or None})]``: every scheme that
    has no strategy in its name, with its ``NAME+STRATEGY`` rows (None when not run)."""
    rows = {r["scheme"]: r for _, r in summary.iterrows()}
    return [(name, {"none": row, **{s: rows.get(f"{name}+{s}") for s in strategies}})
            for name, row in rows.items() if "+" not in name]


def paired_markdown(summary, strategies):
    """Every scheme beside its variants ``NAME+STRATEGY`` (issue #44: every scheme with
    and without remeshing): the meshes taken to the end without and with thin features,
    one column per strategy; ``""`` without strategies."""
    if not strategies:
        return ""

    def count(row, prefix):
        if row is None:
            return "not run"
        k, n = row[f"{prefix}reached"], row[f"{prefix}meshes"]
        return f"{k}/{n}" if n else "–"

    kinds = ["none", *strategies]
    header = ["scheme", *(f"{k if k == 'none' else '+' + k}, {part}"
                          for part in ("without thin features", "with thin features")
                          for k in kinds)]
    cells = [[name, *(count(rows[k], prefix) for prefix in ("plain_", "thin_") for k in kinds)]
             for name, rows in paired_rows(summary, strategies)]
    notes = ["Meshes taken to the end (reached / run) by each scheme as it is (none) and "
             "with each mesh strategy (NAME+STRATEGY), on the same meshes and settings."]
    return markdown(Table(header, cells, notes=notes))
