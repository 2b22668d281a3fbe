"""The survival study's findings, worded from its scheme table only (:func:`findings`)."""

import numpy as np

TARGET = 0.9
"""The share of the meshes without thin features that some scheme should take to the
end (issue #44's target)."""


def findings(summary, plan):
    """A few sentences read from :func:`mcfbench.studies.survival.tables.survival_table`.

    Returns
    -------
    str
        Markdown: the best scheme on the meshes without thin features against
        :data:`TARGET`, the best DDFV variant, the best on the meshes with thin
        features, and when the runs that did not reach the end broke down.
    """
    from mcfbench.running.schemes import find_scheme

    def best(rows, column):
        rows = rows[np.isfinite(rows[column])]
        if not len(rows):
            return None
        top = rows[column].max()
        return rows[rows[column] == top]

    def named(rows, prefix):
        k, n = int(rows.iloc[0][f"{prefix}reached"]), int(rows.iloc[0][f"{prefix}meshes"])
        return f"{', '.join(rows['scheme'])} ({k} of {n}, {100 * k / n:.0f} %)"

    lines = ["# Survival on raw meshes: findings", "",
             f"Every number below is read from `survival.csv`: {len(summary)} schemes on the "
             f"{len(plan['meshes'])} raw meshes the intake reads, {plan['steps']} steps of "
             f"{plan['C']:g} h^2."]
    conformal = [getattr(find_scheme(s), "tangential", "") == "conformal"
                 for s in summary["scheme"]]
    plain = best(summary[[not c for c in conformal]], "plain_share")
    if plain is not None:
        met = "meets" if plain.iloc[0]["plain_share"] >= TARGET else "misses"
        lines += ["", f"- **Without thin features**: of the mean curvature flows, the most "
                      f"are taken to the end by {named(plain, 'plain_')}: it {met} the target "
                      f"of {TARGET:.0%}."]
        frozen = best(summary[conformal], "plain_share")
        if frozen is not None:
            lines.append(f"- Conformalized MCF, whose stiffness is the initial mesh's (not a "
                         f"mean curvature flow): {named(frozen, 'plain_')}.")
    ddfv = summary[[getattr(find_scheme(s), "family", "") == "ddfv" for s in summary["scheme"]]]
    top = best(ddfv, "plain_share")
    if top is not None:
        lines.append(f"- **The best DDFV variant** there: {named(top, 'plain_')}.")
    thin = best(summary, "thin_share")
    if thin is not None:
        lines.append(f"- **With thin features** (the flow pinches them): "
                     f"{named(thin, 'thin_')}.")
    lines += strategy_findings(summary, plan.get("strategies", []))
    lines += through(summary, plan)
    median = np.nanmedian(summary["defect_fraction_median"]) \
        if np.isfinite(summary["defect_fraction_median"]).any() else np.nan
    if np.isfinite(median):
        lines.append(f"- The runs that did not reach the end broke down early: the median "
                     f"scheme's median first defect came at {median:.0%} of the final time.")
    return "\n".join(lines) + "\n"


def strategy_findings(summary, strategies):
    """One sentence per mesh strategy: on the meshes without thin features, for how many
    schemes ``NAME+STRATEGY`` took more, fewer or as many meshes to the end as ``NAME``,
    and the largest gain (read from the table's pairs,
    :func:`mcfbench.studies.survival.tables.paired_rows`)."""
    from mcfbench.studies.survival.tables import paired_rows

    lines = []
    for strategy in strategies:
        diffs = [(name, int(rows["none"]["plain_reached"]), int(rows[strategy]["plain_reached"]))
                 for name, rows in paired_rows(summary, [strategy])
                 if rows[strategy] is not None and rows["none"]["plain_meshes"]
                 and rows[strategy]["plain_meshes"] == rows["none"]["plain_meshes"]]
        if not diffs:
            continue
        more = sum(b > a for _, a, b in diffs)
        fewer = sum(b < a for _, a, b in diffs)
        name, a, b = max(diffs, key=lambda d: d[2] - d[1])
        gain = f"; the largest gain: {name} ({a} -> {b})" if b > a else ""
        lines.append(f"- **+{strategy}** beside each scheme, without thin features: more "
                     f"meshes taken to the end for {more} of {len(diffs)} schemes, fewer "
                     f"for {fewer}, as many for {len(diffs) - more - fewer}{gain}.")
    return lines


def through(summary, plan):
    """The findings' lines on the ``NAME+surgery`` schemes (the continuation through a
    neck pinch and the thin parts' singularities): which took meshes with thin features
    to the end, and which none; nothing when the study ran none. ``plan``'s
    ``max_removed_share``: the share of the area a counted run's continuations may
    remove (:func:`mcfbench.studies.survival.plan.plan`)."""
    continued = summary[summary["scheme"].str.endswith("+surgery")
                        & (summary["thin_meshes"] > 0)]
    if not len(continued):
        return []
    went = continued[continued["thin_reached"] > 0].sort_values("thin_reached",
                                                                ascending=False)
    names = ", ".join(f"{r.scheme} ({int(r.thin_reached)} of {int(r.thin_meshes)})"
                      for r in went.itertuples())
    stuck = ", ".join(continued.loc[continued["thin_reached"] == 0, "scheme"])
    through = continued[continued["thin_through"] > 0].sort_values("thin_through",
                                                                   ascending=False)
    past = ", ".join(f"{r.scheme} ({int(r.thin_through)})" for r in through.itertuples())
    return [f"- **Through the singularities** (`NAME+surgery`: a pinched neck cut, the "
            f"parts thinner than the mesh re-extracted, a run counted only when its "
            f"continuations removed at most {plan['max_removed_share']:.0%} of the area): "
            + (f"{names} took meshes with thin features to the end" if len(went) else
               "none took a mesh with thin features to the end")
            + (f"; {stuck} none." if stuck else ".")
            + (f" Runs that went on past a continuation to the end, whatever the share "
               f"removed: {past}." if past else
               " No run went on past a continuation to the end.")]
