"""The scaling study (issue #32): for every scheme of the levels table, the CPU seconds
of one time step and the peak memory against the number of unknowns, with the
power laws ``c n^p`` fitted in log-log on the finest levels.

The points are the finished runs of the levels table (runs of the run store: a
batch job runs several in one process, so a run's ``peak_rss_mb`` is the process's
peak so far, that of the batch's earlier runs included), nothing is run again:

* ``n``: the unknowns of the run (``RunResult.nV``: DDFV's F- plus T-vertices,
  the mesh vertices otherwise);
* ``step_seconds``: the run's CPU seconds (the flow alone: construction, steps,
  error; warm-up excluded, :func:`mcfbench.running.run.warm_up`) over its steps;
* ``memory_mb``: the job's peak resident memory (``peak_rss_mb``) above that of
  the scheme's coarsest run of the table (the part every job of the scheme
  takes on whatever its size: imports, compiled kernels, warm-up), so that the
  slope is the one of the memory that grows with the mesh.
"""

import numpy as np
import pandas as pd

from mcfbench.presentation.formats import MISSING, fix, int_or, sig
from mcfbench.studies.convergence.tables import label

SCALING_COLUMNS = ["scheme", "label", "fit_levels", "n_min", "n_max", "step_seconds",
                   "step_coefficient", "step_slope", "peak_rss_mb", "fixed_mb",
                   "memory_mb", "memory_coefficient", "memory_slope"]
"""One row per scheme: the unknowns of its coarsest and finest fitted runs, the
CPU seconds per step and the memory of the finest, the fits ``c n^p`` of both."""


def power_fit(n, y):
    """``(c, p)`` of the power law ``y = c n^p``: least squares on ``log y`` against
    ``log n``.

    Parameters
    ----------
    n, y : array_like, shape (k,)
        Positive sizes and values.

    Returns
    -------
    c, p : float
        NaN both when fewer than two points are given or a value is not positive
        (no power law to fit).
    """
    n, y = np.asarray(n, dtype=float), np.asarray(y, dtype=float)
    if len(n) < 2 or len(np.unique(n)) < 2 or not (np.all(n > 0) and np.all(y > 0)):
        return float("nan"), float("nan")
    slope, intercept = np.polyfit(np.log(n), np.log(y), 1)
    return float(np.exp(intercept)), float(slope)


def scaling_points(levels):
    """The levels table with the columns of the scaling study.

    Parameters
    ----------
    levels : pandas.DataFrame
        The levels table (columns ``scheme``, ``level``, ``N``, ``cpu_seconds``,
        ``peak_rss_mb``, ``status``).

    Returns
    -------
    pandas.DataFrame
        ``levels`` with ``step_seconds`` (CPU seconds per step, NaN for a run
        that did not finish) and ``memory_mb`` (peak memory above the peak of
        the scheme's coarsest run).
    """
    ok = levels["status"] == "ok"
    fixed = levels.sort_values("level").groupby("scheme")["peak_rss_mb"].transform("first")
    return levels.assign(step_seconds=(levels["cpu_seconds"] / levels["N"]).where(ok),
                         memory_mb=levels["peak_rss_mb"] - fixed.reindex(levels.index))


def scaling_table(levels, fit_levels):
    """One row per scheme (:data:`SCALING_COLUMNS`): the power laws fitted on the
    finished runs of its ``fit_levels``.

    Parameters
    ----------
    levels : pandas.DataFrame
        :func:`scaling_points` of the levels table.
    fit_levels : sequence of int, or dict
        The levels of the fits, or scheme -> its levels of the fits (a scheme
        with fewer than two finished runs among them has NaN fits).
    """
    rows = []
    for scheme in dict.fromkeys(levels["scheme"]):
        runs = levels[levels["scheme"] == scheme].sort_values("level")
        fit = fit_levels[scheme] if isinstance(fit_levels, dict) else fit_levels
        fitted = runs[runs["level"].isin(fit) & np.isfinite(runs["step_seconds"])]
        step = power_fit(fitted["nV"], fitted["step_seconds"])
        memory = power_fit(fitted["nV"], fitted["memory_mb"])
        finest = fitted.iloc[-1] if len(fitted) else pd.Series(dtype=float)
        rows.append({"scheme": scheme, "label": label(scheme),
                     "fit_levels": " ".join(str(lv) for lv in fitted["level"]),
                     "n_min": fitted["nV"].min(), "n_max": fitted["nV"].max(),
                     "step_seconds": finest.get("step_seconds", np.nan),
                     "step_coefficient": step[0], "step_slope": step[1],
                     "peak_rss_mb": finest.get("peak_rss_mb", np.nan),
                     "fixed_mb": (runs["peak_rss_mb"] - runs["memory_mb"]).iloc[0],
                     "memory_mb": finest.get("memory_mb", np.nan),
                     "memory_coefficient": memory[0], "memory_slope": memory[1]})
    return pd.DataFrame(rows, columns=SCALING_COLUMNS)


def scaling_rows(table):
    """``(header, rows)`` of the scaling table, one row per scheme."""
    header = ["scheme", "levels fitted", "unknowns", "CPU s/step (finest)", "slope CPU/step",
              "peak MB (finest)", "MB of the coarsest run", "MB above it (finest)",
              "slope memory"]
    rows = [[r.label, r.fit_levels or MISSING,
             f"{int_or(r.n_min)}-{int_or(r.n_max)}" if np.isfinite(r.n_min) else MISSING,
             sig(r.step_seconds, 3), fix(r.step_slope, 2), int_or(r.peak_rss_mb),
             int_or(r.fixed_mb), int_or(r.memory_mb), fix(r.memory_slope, 2)]
            for r in table.itertuples()]
    return header, rows
