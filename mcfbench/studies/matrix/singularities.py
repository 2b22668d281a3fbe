"""Which schemes go through singularities, from the matrix's long table (issue #45): the
section "Through singularities" of the findings.

A problem is in it when one of its runs ended ``extinct`` (:data:`EXTINCT`): the
dumbbell through its pinch (every scheme as ``NAME+surgery``, to both bulbs'
extinction) and the torus (2, 0.5), which collapses onto its core circle at its
singular time. Per scheme (:func:`singularity_frame`): each level's status (the robust
solver's re-run in place of a run whose failure it removes, as the verdicts do), and at
the finest level every run of the scheme reached, the errors of :data:`METRICS` it
measured with their EOC from the level before. A scheme *goes through* a problem when
every level reached the flow's end (:data:`mcfbench.storage.statuses.REACHED`).
"""

import numpy as np

from mcfbench.presentation.formats import formatted
from mcfbench.presentation.tables import Table, markdown
from mcfbench.storage.statuses import REACHED
from mcfbench.studies.matrix.tables import solver_only

EXTINCT = "extinct"
"""The status of a run whose flow reached its end: its last component vanished."""

METRICS = (("extinction_time_error", "extinction time"), ("pinch_time_error", "pinch time"),
           ("bulb_volume_error", "bulb volume after the pinch"))
"""The errors shown (relative; the extinction and pinch times' signed), when measured."""


def singular_problems(table):
    """The problems of the long table with a run that ended ``extinct``, in its order."""
    return list(dict.fromkeys(table.loc[table["status"] == EXTINCT, "problem"]))


def _view(rows):
    """``rows`` (one metric's, one run a row) with the robust re-run in place of a run
    whose failure it removes (:func:`mcfbench.studies.matrix.tables.solver_only`)."""
    rows = rows.copy()
    fixed = rows.apply(solver_only, axis=1).astype(bool) if len(rows) else rows["status"]
    rows.loc[fixed, "status"] = rows.loc[fixed, "robust_status"]
    rows.loc[fixed, "value"] = rows.loc[fixed, "robust_value"]
    return rows


def singularity_frame(table, problem):
    """One row per scheme of ``problem``: ``scheme``, ``statuses`` (``"L1 extinct, L2
    t_escaped"``), ``through`` (every level reached its end), ``finest`` (the finest
    level every run up to it reached, NaN for none) and, per metric of :data:`METRICS`
    the problem measured, ``<metric>`` (its value there) and ``<metric>_eoc`` (from the
    level before, NaN without one).

    Returns
    -------
    pandas.DataFrame
    """
    import pandas as pd

    part = table[table["problem"] == problem]
    metrics = [m for m, _ in METRICS if m in set(part["metric"])]
    rows = []
    for scheme in dict.fromkeys(part["scheme"]):
        mine = part[part["scheme"] == scheme]
        first = _view(mine[mine["metric"] == mine["metric"].iloc[0]]).sort_values("level")
        reached = first["status"].isin(REACHED).to_numpy()
        levels = first["level"].to_numpy()
        upto = int(np.argmin(reached)) if not reached.all() else len(levels)
        row = {"scheme": scheme,
               "statuses": ", ".join(f"L{lv} {st}" for lv, st in zip(levels, first["status"])),
               "through": bool(reached.all()),
               "finest": int(levels[upto - 1]) if upto else np.nan}
        for metric in metrics:
            series = _view(mine[mine["metric"] == metric]).set_index("level")["value"]
            value = series.get(row["finest"], np.nan) if upto else np.nan
            before = series.get(row["finest"] - 1, np.nan) if upto else np.nan
            row[metric] = value
            row[f"{metric}_eoc"] = (np.log2(abs(before) / abs(value))
                                    if np.isfinite(before) and np.isfinite(value) and value
                                    and before else np.nan)
        rows.append(row)
    return pd.DataFrame(rows)


def singularity_section(table):
    """The findings' section "Through singularities" (module docstring), a sentence and a
    table per problem, or nothing when no run ended ``extinct``."""
    problems = singular_problems(table)
    if not problems:
        return []
    lines = ["## Through singularities", "",
             "The problems where a run reached the flow's end (its last component vanished, "
             "`extinct`): per scheme, each level's status and, at the finest level every "
             "run up to it reached, the relative errors (the times' signed) with their EOC "
             "from the level before.", ""]
    for problem in problems:
        frame = singularity_frame(table, problem)
        through = list(frame.loc[frame["through"], "scheme"])
        stopped = frame[~frame["through"]]
        lines += [f"### {problem}", "",
                  f"{len(through)} of the {len(frame)} schemes go through at every level"
                  + (f" ({', '.join(through)})" if through else "") + "."
                  + (f" The others stop: " + "; ".join(
                      f"{r['scheme']} ({r['statuses']})" for _, r in stopped.iterrows()) + "."
                     if len(stopped) else ""), ""]
        columns = [("scheme", "scheme", None),
                   ("finest", "finest level reached", lambda v: formatted(v, ".0f"))]
        for metric, label in METRICS:
            columns += [(metric, label, lambda v: formatted(v, "+.3g")),
                        (f"{metric}_eoc", "EOC", lambda v: formatted(v, ".2f"))]
        table_ = Table.of_frame(frame, columns=columns)
        lines += [markdown(table_), ""]
    return lines
