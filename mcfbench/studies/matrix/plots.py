"""Plots of the benchmark matrix (PNG and PDF, written atomically).

* :func:`error_figure`: the main metric against ``h`` per problem, every
  scheme, with slope-2 guides; a problem without an exact error shows the
  time each run reached (the breakdown time) against ``h`` instead;
* :func:`quality_figure`: the smallest angle and the DDFV T monitor over
  time per problem (finest level of each scheme, from the records'
  ``series``);
* :func:`picture_grid`: the final surfaces, scheme x problem, from the
  saved frames (:mod:`mcfbench.presentation.picture_grid`; the gallery's grid
  is :func:`mcfbench.studies.gallery.plots.gallery_grid`).
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from mcfbench.presentation.picture_grid import draw_grid, last_frames, run_note  # noqa: E402
from mcfbench.presentation.plots import SMALLEST_TEXT  # noqa: E402
from mcfbench.presentation.plots import style as scheme_style  # noqa: E402
from mcfbench.storage.atomic import save_figure  # noqa: E402
from mcfbench.storage.statuses import reached  # noqa: E402
from mcfbench.studies.matrix.tables import is_error, main_runs  # noqa: E402

T_FLOOR = -0.5
"""Lower limit of the T monitor axes (values below are clipped and noted)."""
PER_ROW = 3
"""Panels per row of the error and quality figures: 3 x 3.4 in, within a laptop's
column (about 12.4 in at 1280 px) at print size."""
VIEWS = {"catenoid": (15.0, -60.0), "hemisphere": (25.0, -60.0)}
"""View (elev, azim) of the pictures per problem (default ``(20, -60)``)."""


def _grid(n, width=3.4, height=3.0, rows=1):
    cols = int(np.ceil(n / rows))
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False)
    for ax in axes.ravel()[n:]:
        ax.set_axis_off()
    return fig, axes


def _legend(fig, schemes):
    """One legend for the whole figure (the schemes' registry styles)."""
    from matplotlib.lines import Line2D

    handles = []
    for scheme in schemes:
        label, style = scheme_style(scheme)
        handles.append(Line2D([], [], label=label, **style))
    fig.legend(handles=handles, loc="lower center", ncol=min(4, len(handles)),
               fontsize=SMALLEST_TEXT, frameon=False)


def _log_axis(axis):
    from matplotlib.ticker import NullFormatter

    axis.set_minor_formatter(NullFormatter())


def error_figure(table, paths, problems=None, schemes=None):
    """Main metric (absolute value) against ``h``, log-log, one panel per problem.

    Runs that did not finish are left out and their schemes named in the
    panel ("broke down: ..."); a zero error (exact) cannot be drawn on a log
    axis and is named too. Dotted slope-2 guides go through the smallest and
    largest error at the finest ``h``. A problem whose main metric is not
    an error shows the time each run reached (the breakdown time of a run
    that broke down) against ``h``.
    """
    problems = problems or list(dict.fromkeys(table["problem"]))
    schemes = schemes or list(dict.fromkeys(table["scheme"]))
    rows_ = int(np.ceil(len(problems) / PER_ROW))
    fig, axes = _grid(len(problems), rows=rows_)
    for problem, ax in zip(problems, axes.ravel()):
        runs, metric = main_runs(table, problem)
        error = is_error(metric)
        points, broke, exact = [], [], []
        for scheme in schemes:
            rows = runs[runs["scheme"] == scheme].sort_values("level")
            if not len(rows):
                continue
            label, style = scheme_style(scheme)
            if not rows["status"].map(reached).all():       # ok or extinct: reached
                broke.append(scheme)
            if error:     # a value measured before a later breakdown (the pinch) counts
                ok = rows[np.isfinite(rows["value"])]
                x, y = ok["h"].to_numpy(), np.abs(ok["value"].to_numpy())
                if len(y) and (y == 0).all():
                    exact.append(scheme)
                keep = y > 0
                x, y = x[keep], y[keep]
            else:
                x = rows["h"].to_numpy()
                y = np.where(rows["status"] == "ok", rows["steps_done"] * rows["tau"],
                             rows["t_failed"])
            ax.plot(x, y, label=label, **style)
            points += [(a, b) for a, b in zip(x, y) if np.isfinite(b) and b > 0]
        if error and points:
            xs = np.array([p[0] for p in points])
            ys = np.array([p[1] for p in points])
            h = np.array([xs.min(), xs.max()])
            if h[1] > h[0]:
                for anchor in (ys[xs == xs.min()].min(), ys[xs == xs.min()].max()):
                    ax.plot(h, anchor * (h / h[0]) ** 2, color="0.6", lw=0.8, ls=":")
                ax.text(h[1], ys[xs == xs.min()].max() * (h[1] / h[0]) ** 2, "slope 2",
                        fontsize=SMALLEST_TEXT, color="0.4", ha="right", va="bottom")
        if error and points:
            ax.set_yscale("log")
            _log_axis(ax.yaxis)
        ax.set_xscale("log")
        _log_axis(ax.xaxis)
        notes = []
        if broke:
            notes.append("broke down: " + ", ".join(broke))
        if exact:
            notes.append("error 0 (exact): " + ", ".join(exact))
        if notes:
            ax.text(0.02, 0.98, "\n".join(_wrap(n) for n in notes), transform=ax.transAxes,
                    ha="left", va="top", fontsize=SMALLEST_TEXT, color="0.2",
                    bbox={"fc": "white", "ec": "0.8", "alpha": 0.85, "pad": 1.5})
        ax.set_xlabel("h (mean edge length)")
        ax.set_ylabel(f"|{metric}|" if error else "time reached (breakdown)")
        ax.set_title(problem)
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
    fig.suptitle("Benchmark matrix: main metric against h", fontsize=10)
    fig.tight_layout(rect=(0, 0.06 / rows_, 1, 1))
    _legend(fig, schemes)
    save_figure(fig, *paths)


WORK_PRECISION_NOTE = ("CPU seconds of one run on one core, the problem's solver rule for "
                       "every scheme (same footing within a panel)")


def work_precision_figure(table, paths, problems=None, schemes=None):
    """Work-precision diagram: the main error of every run against its CPU
    seconds, log-log, one panel per problem with an error metric, one line per
    scheme through its levels (runs whose value is not finite left out).

    Timings are on the same footing within a panel (one core, the same solver
    rule and tolerance for every scheme of a problem); the figure says so.

    Returns
    -------
    dict
        ``{problem: {scheme: (cpu_seconds, |error|)}}``: the points drawn.
    """
    problems = problems or list(dict.fromkeys(table["problem"]))
    schemes = schemes or list(dict.fromkeys(table["scheme"]))
    shown = []
    for problem in problems:
        runs, metric = main_runs(table, problem)
        if is_error(metric):
            shown.append((problem, metric, runs))
    rows_ = max(1, int(np.ceil(len(shown) / PER_ROW)))
    fig, axes = _grid(max(1, len(shown)), rows=rows_)
    drawn = {}
    for (problem, metric, runs), ax in zip(shown, axes.ravel()):
        for scheme in schemes:
            rows = runs[(runs["scheme"] == scheme) & np.isfinite(runs["value"])
                        & (runs["value"] != 0)].sort_values("level")
            if len(rows):
                label, style = scheme_style(scheme)
                x, y = rows["cpu_seconds"].to_numpy(), np.abs(rows["value"].to_numpy())
                ax.plot(x, y, label=label, **style)
                drawn.setdefault(problem, {})[scheme] = (x, y)
        ax.set_xscale("log")
        ax.set_yscale("log")
        _log_axis(ax.xaxis)
        _log_axis(ax.yaxis)
        ax.set_xlabel("CPU seconds (one core)")
        ax.set_ylabel(f"|{metric}|")
        ax.set_title(problem)
        ax.grid(True, which="both", lw=0.3, alpha=0.5)
    fig.suptitle(f"Benchmark matrix: error against cost ({WORK_PRECISION_NOTE})", fontsize=9)
    fig.tight_layout(rect=(0, 0.06 / rows_, 1, 1))
    _legend(fig, schemes)
    save_figure(fig, *paths)
    return drawn


def _wrap(text, width=40):
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


def quality_figure(records, paths, problems=None, schemes=None):
    """Smallest angle (top) and T monitor (bottom, DDFV) over time, finest level."""
    by_run = {}
    for r in records:
        key = (r["problem"], r["scheme"])
        if key not in by_run or r["level"] > by_run[key]["level"]:
            by_run[key] = r
    problems = problems or list(dict.fromkeys(p for p, _ in by_run))
    schemes = schemes or list(dict.fromkeys(s for _, s in by_run))
    cols = min(PER_ROW, len(problems))
    rows = int(np.ceil(len(problems) / cols))
    fig, axes = plt.subplots(2 * rows, cols, figsize=(3.4 * cols, 5.6 * rows), squeeze=False)
    for ax in axes[:, :].ravel():
        ax.set_visible(False)
    for j, problem in enumerate(problems):
        top, bottom = axes[2 * (j // cols), j % cols], axes[2 * (j // cols) + 1, j % cols]
        top.set_visible(True)
        bottom.set_visible(True)
        levels = set()
        for scheme in schemes:
            r = by_run.get((problem, scheme))
            if r is None or not r.get("series"):
                continue
            levels.add(int(r["level"]))
            label, style = scheme_style(scheme)
            style = {k: v for k, v in style.items() if k != "marker"}
            series = r["series"]
            t, angle = np.asarray(series.get("quality_t", []), float), \
                np.asarray(series.get("min_angle", []), float)
            if len(t):
                top.plot(t, angle, label=label, **style)
                if r["status"] != "ok":
                    top.plot(t[-1:], angle[-1:], "x", color=style.get("color"), ms=6)
            tm = np.asarray([np.nan if v is None else v
                             for v in series.get("t_min_barycentric", [])], float)
            if np.isfinite(tm).any():
                tt = np.asarray(series["t"], float)
                bottom.plot(tt, tm, label=label, **style)
                if r["status"] != "ok":
                    bottom.plot(tt[-1:], tm[-1:], "x", color=style.get("color"), ms=6)
        top.set_title(f"{problem} (level {', '.join(map(str, sorted(levels)))})")
        top.set_ylabel("smallest angle (degrees)")
        bottom.set_ylabel("T monitor (min barycentric)")
        bottom.axhline(0.0, color="0.5", lw=0.6)
        lows = [min(line.get_ydata()) for line in bottom.lines if len(line.get_ydata())]
        if lows and min(lows) < T_FLOOR:  # a T-vertex far outside: keep 0 readable
            bottom.set_ylim(T_FLOOR, 0.36)
            bottom.text(0.98, 0.02, f"clipped at {T_FLOOR} (lowest {min(lows):.3g})",
                        transform=bottom.transAxes, ha="right", va="bottom",
                        fontsize=SMALLEST_TEXT)
        bottom.set_xlabel("t")
        for ax in (top, bottom):
            ax.grid(True, lw=0.3, alpha=0.5)
    fig.suptitle("Mesh quality over time (finest level; x = breakdown)", fontsize=10)
    fig.tight_layout(rect=(0, 0.04 / rows, 1, 1 - 0.03 / rows))
    _legend(fig, schemes)
    save_figure(fig, *paths)


def picture_grid(entries, paths, problems, schemes):
    """Final surfaces, schemes as rows (the initial surface first), problems as columns.

    Parameters
    ----------
    entries : dict
        ``(problem, scheme) -> (record, frames)``, ``frames`` a mapping of
        the saved arrays (``np.load`` of the npz).
    """
    columns = last_frames(entries, problems, schemes,
                          lambda record: f"L{record['level']}: {run_note(record)}",
                          lambda record, _: f"level {record['level']}, t = 0")
    cells = [list(row) for row in zip(*columns)]
    labels = ["initial"] + [scheme_style(s)[0] for s in schemes]
    draw_grid(cells, labels, problems, paths, "Final surfaces (coarsest level of each problem)",
               views=[VIEWS.get(p, (20.0, -60.0)) for p in problems])


