"""Plots of the pipeline's tables: the convergence figure and the beyond figures.

Every scheme is drawn with the label and the line style of its registry
entry (:data:`mcfbench.running.schemes.SCHEMES`), so a new scheme needs no entry
here. A run that broke down has no error: it is marked by a cross at the
bottom of the axes, at its mesh size, in the colour of its scheme.

:func:`convergence_figure`
    L2 error (3.2) against h, log-log, every scheme, the published DDFV
    errors of Table 3.1 as open markers, a slope-2 guide.
:func:`beyond_figures`
    ``levels`` (as the convergence figure for every level, and ours over
    the published error below), ``t_monitor`` (the T monitor against time,
    one panel per scheme with T-vertices), ``time_convergence``,
    ``space_convergence`` and ``scaling`` (CPU seconds per step and memory
    against the unknowns, log-log, each scheme's fitted slope in the legend).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FixedFormatter, FixedLocator, NullFormatter  # noqa: E402

from mcfbench.presentation.formats import fix  # noqa: E402
from mcfbench.running.schemes import find_scheme  # noqa: E402
from mcfbench.storage.statuses import reached  # noqa: E402

SMALLEST_TEXT = 8
"""The smallest text of a figure on a results page, in points: the matrix's page shows
its figures at print size (``mcfbench.studies.matrix.page.print_width``), so this is
what a reader sees."""
EDGE = 1.0 / 3.0   # 1/3 - monitor at which a T-vertex reaches an edge of its triangle
UNREGISTERED = {"color": "k", "marker": "x", "linestyle": "-"}


def style(scheme):
    """``(label, line style dict)`` of ``scheme`` from the registry."""
    entry = find_scheme(scheme)
    if entry is None:
        return scheme, dict(UNREGISTERED)
    return entry.label, {**UNREGISTERED, **entry.style}


def mathtext_number(x):
    """``9.765625e-06`` as mathtext ``9.77 \\cdot 10^{-6}`` (from 1e-3 up: ``%g``)."""
    if x >= 1e-3:
        return f"{x:g}"
    mantissa, exponent = f"{x:.2e}".split("e")
    return f"{float(mantissa):g} \\cdot 10^{{{int(exponent)}}}"


def scheme_lines(ax, table, x, y):
    """One line ``y`` against ``x`` per scheme, through its finished rows.

    Returns the finished rows (status ``ok``, finite ``y``).
    """
    ok = table[(table["status"] == "ok") & np.isfinite(table[y])]
    for scheme in table["scheme"].unique():
        rows = ok[ok["scheme"] == scheme].sort_values(x)
        label, line = style(scheme)
        ax.plot(rows[x], rows[y], label=label, markersize=5, linewidth=1.5, **line)
    return ok


def slope_guide(ax, ok, x, y, order, label):
    """A dashed ``x**order`` guide through half the smallest ``y`` at the smallest ``x``."""
    if len(ok):
        xs = np.array([ok[x].min(), ok[x].max()])
        smallest = ok[ok[x] == ok[x].min()][y].min()
        ax.plot(xs, 0.5 * smallest * (xs / xs[0]) ** order, linestyle="--", color="0.5",
                linewidth=1.0, label=label)


def failure_marks(ax, table, x):
    """A cross at the bottom of the axes for every row that did not finish (any
    status but ``ok`` and ``extinct``, :data:`mcfbench.storage.statuses.REACHED`), in
    the colour of its scheme."""
    failed = table[~table["status"].map(reached).astype(bool)]
    for i, r in enumerate(failed.itertuples()):
        ax.plot([getattr(r, x)], [0.03 + 0.05 * (i % 3)], linestyle="none", marker="x",
                markersize=8, markeredgewidth=2, color=style(r.scheme)[1]["color"],
                transform=ax.get_xaxis_transform(), clip_on=False,
                label="broke down (no error)" if i == 0 else None)


def draw_convergence(ax, table, t_final, note=None):
    """The convergence plot of ``table`` (the convergence CSV) into ``ax``.

    ``note`` replaces the text in the lower right corner (default: shrinking
    sphere, ``tau ~ h^2``, ``t_f``).
    """
    ok = scheme_lines(ax, table, "h", "l2_error")
    failure_marks(ax, table, "h")
    paper = table[np.isfinite(table["paper_l2_error"])].sort_values("h")
    if len(paper):
        ax.plot(paper["h"], paper["paper_l2_error"], linestyle="none", marker="o",
                markersize=10, markerfacecolor="none", markeredgecolor="black",
                markeredgewidth=1.0, label="DDFV, Table 3.1 (paper)")
    slope_guide(ax, ok, "h", "l2_error", 2, r"slope 2 ($\propto h^2$)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    levels = table.drop_duplicates("level").sort_values("h")
    ax.xaxis.set_major_locator(FixedLocator(levels["h"]))
    ax.xaxis.set_major_formatter(FixedFormatter([f"{h:.3g}" for h in levels["h"]]))
    ax.xaxis.set_minor_formatter(NullFormatter())
    top = ax.secondary_xaxis("top")
    top.set_xticks(levels["h"], labels=[str(level) for level in levels["level"]])
    top.xaxis.set_minor_formatter(NullFormatter())
    top.set_xlabel("refinement level", fontsize=9)
    ax.set_xlabel(r"mesh size $h$ (mean edge length)")
    ax.set_ylabel(r"space-time $L_2$ error")
    if note is None:
        note = "shrinking unit sphere\n" rf"$\tau \sim h^2$, $t_f = {t_final:g}$"
    ax.text(0.97, 0.04, note, transform=ax.transAxes, ha="right", va="bottom", fontsize=8)
    ax.grid(True, which="major", linewidth=0.5, alpha=0.5)
    ax.grid(True, which="minor", axis="y", linewidth=0.3, alpha=0.25)
    ax.legend(fontsize=8, loc="upper left", frameon=False)


def convergence_figure(table, t_final):
    """The convergence figure of ``table`` (the convergence CSV as a DataFrame)."""
    fig, ax = plt.subplots(figsize=(5.2, 4.0), layout="constrained")
    draw_convergence(ax, table, t_final)
    return fig


# -- beyond Table 3.1 -------------------------------------------------------------------

def levels_figure(table, t_final):
    """L2 error per level for every scheme, and the ratio to the paper below."""
    fig, (ax, bottom) = plt.subplots(2, 1, figsize=(6.0, 6.4), sharex=True,
                                     height_ratios=[3, 1.3], layout="constrained")
    draw_convergence(ax, table, t_final)
    ax.set_xlabel("")
    ax.set_title("L2 error per level and scheme", fontsize=10)
    ratio = table[np.isfinite(table["l2_ratio"])]
    for scheme in ratio["scheme"].unique():
        rows = ratio[ratio["scheme"] == scheme].sort_values("h")
        label, line = style(scheme)
        bottom.plot(rows["h"], rows["l2_ratio"], markersize=5, linewidth=1.2, label=label,
                    **line)
    bottom.axhline(1.0, color="black", linewidth=0.8, linestyle=":")
    bottom.set_ylabel("L2 ours / paper", fontsize=9)
    bottom.set_xlabel(r"mesh size $h$ (mean edge length)")
    bottom.grid(True, linewidth=0.5, alpha=0.5)
    bottom.xaxis.set_minor_formatter(NullFormatter())
    return fig


def t_monitor_figure(series, stability, schemes):
    """The T monitor against time, per scheme and level (log of 1/3 - monitor)."""
    schemes = [s for s in schemes if s in set(series["scheme"])] or \
        list(dict.fromkeys(series["scheme"])) or ["(none)"]
    fig, axes = plt.subplots(1, len(schemes), figsize=(3.6 * len(schemes) + 0.6, 4.2),
                             sharey=True, squeeze=False, layout="constrained")
    levels = sorted(series.loc[series["study"] == "levels", "level"].unique())
    colours = dict(zip(levels, plt.get_cmap("viridis")(
        np.linspace(0.0, 0.9, max(len(levels), 1)))))
    t_max = series["t"].max() if len(series) else 1.0
    deficit = EDGE - series["t_monitor"].to_numpy(dtype=float)
    deficit = deficit[np.isfinite(deficit)]
    positive = deficit[deficit > 0]
    bottom = 10.0 ** np.floor(np.log10(positive.min())) if len(positive) else 1e-3
    top = max(60.0, 2.0 * deficit.max()) if len(deficit) else 60.0
    for ax, scheme in zip(axes[0], schemes):
        ax.axhspan(EDGE, 10 * top, color="tab:red", alpha=0.07, linewidth=0)
        ax.axhline(EDGE, color="tab:red", linewidth=0.9, linestyle="--")
        ax.text(0.97, 0.985, "T-vertex outside its triangle (monitor < 0)", color="tab:red",
                transform=ax.transAxes, ha="right", va="top", fontsize=7)
        # the long run first: the level lines of the same level go on top of it
        for study in ("long_time", "levels"):
            part = series[(series["scheme"] == scheme) & (series["study"] == study)]
            for level in sorted(part["level"].unique()):
                run = part[part["level"] == level]
                if study == "levels":
                    ax.plot(run["t"], EDGE - run["t_monitor"], color=colours.get(level, "k"),
                            linewidth=1.5, label=f"level {level}")
                else:
                    ax.plot(run["t"], EDGE - run["t_monitor"], color="black", linewidth=1.1,
                            dashes=(4, 2),
                            label=f"level {level} to t = {run['t_final'].iloc[0]:g}")
        runs = stability[stability["scheme"] == scheme]
        failed = runs[runs["status"] != "ok"]
        for r in failed.itertuples():
            y = EDGE - r.t_monitor_end
            ax.plot([r.t_reached], [y], marker="X", markersize=9, color="tab:red",
                    markeredgecolor="black", markeredgewidth=0.6, linestyle="none", zorder=5)
            right = r.t_reached < 0.5 * t_max
            what = "long run" if r.study == "long_time" else f"level {r.level}"
            ax.annotate(f"{what}: {r.status} at t = {r.t_failed:.4g}\n"
                        f"(monitor {r.t_monitor_end:.3g} at t = {r.t_reached:.4g})",
                        (r.t_reached, y),
                        xytext=(8, 4) if right else (-8, -4), textcoords="offset points",
                        ha="left" if right else "right", va="bottom" if right else "top",
                        fontsize=7)
        ok = runs[runs["status"] == "ok"]
        worst = ok["t_min_barycentric"].min() if len(ok) else np.nan
        text = "every run finished" if len(failed) == 0 else \
            f"{len(failed)} run(s) broke down (crosses)"
        if np.isfinite(worst):
            text += f"\nsmallest monitor of the\nfinished runs: {worst:.3f}"
        ax.text(0.97, 0.03, text, transform=ax.transAxes, ha="right", va="bottom",
                fontsize=7.5)
        ax.set_yscale("log")
        ax.set_ylim(max(bottom, 1e-5), top)
        ax.set_xlim(0, t_max * 1.02)
        ax.set_title(style(scheme)[0], fontsize=10)
        ax.set_xlabel("time t")
        ax.grid(True, which="major", linewidth=0.5, alpha=0.5)
    axes[0][0].set_ylabel("1/3 $-$ T monitor  (log scale)")
    fig.suptitle("T monitor = smallest barycentric coordinate of any T-vertex projected into "
                 "its triangle (1/3 at the barycentre, < 0 outside)", fontsize=9)
    handles, labels = axes[0][-1].get_legend_handles_labels()
    if labels:
        order = sorted(range(len(labels)), key=lambda i: (labels[i].count("to t"), labels[i]))
        axes[0][-1].legend([handles[i] for i in order], [labels[i] for i in order],
                           fontsize=7, loc="center right", frameon=False)
    return fig


def time_figure(table):
    """Error at t_f against tau on a fixed mesh, one line per scheme, slope 1."""
    fig, ax = plt.subplots(figsize=(5.2, 4.0), layout="constrained")
    ok = scheme_lines(ax, table, "tau", "error")
    slope_guide(ax, ok, "tau", "error", 1, r"slope 1 ($\propto \tau$)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    taus = np.sort(table["tau"].dropna().unique())
    if len(taus):
        ax.xaxis.set_major_locator(FixedLocator(taus))
        ax.xaxis.set_major_formatter(FixedFormatter([f"{t:g}" for t in taus]))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.tick_params(axis="x", labelsize=7)
    first = table.iloc[0]
    ax.set_xlabel(r"time step $\tau$")
    ax.set_ylabel(r"error at $t_f$ against a fine-$\tau$ reference")
    ax.text(0.97, 0.04, f"icosphere level {first.level} (fixed mesh), "
            f"$t_f = {first.t_final:g}$\nreference $\\tau = {mathtext_number(first.reference_tau)}$",
            transform=ax.transAxes, ha="right", va="bottom", fontsize=8)
    ax.grid(True, which="major", linewidth=0.5, alpha=0.5)
    ax.legend(fontsize=8, loc="upper left", frameon=False)
    ax.set_title("Convergence in time", fontsize=10)
    return fig


def space_figure(table):
    """Error (3.2) against h with one tiny tau, slope 2 (as the convergence figure)."""
    fig, ax = plt.subplots(figsize=(5.2, 4.0), layout="constrained")
    first = table.iloc[0]
    draw_convergence(ax, table.assign(paper_l2_error=np.nan), first.t_final,
                     note=f"shrinking unit sphere\n$\\tau = {mathtext_number(first.tau)}$ on every "
                          f"level, $t_f = {first.t_final:g}$")
    ax.set_title("Convergence in space", fontsize=10)
    return fig


def scaling_figure(levels, scaling, fit_levels):
    """CPU seconds per step and peak memory above the coarsest run against the unknowns.

    Parameters
    ----------
    levels : pandas.DataFrame
        One row per run (columns ``scheme``, ``level``, ``nV``, ``step_seconds``,
        ``memory_mb``, ``status``: the points of
        :func:`mcfbench.studies.beyond.tables.scaling_tables`).
    scaling : pandas.DataFrame
        The scaling table (one row per scheme: ``step_slope``, ``memory_slope``).
    fit_levels : sequence of int
        The levels of the fits (named in the title; a scheme fitted on others,
        ``beyond.scaling.up_to``, has its own in the legend).
    """
    fig, axes = plt.subplots(1, 2, figsize=(10.4, 4.2), layout="constrained")
    slopes = scaling.set_index("scheme")
    default = " ".join(str(lv) for lv in fit_levels)
    own = {s: f" (levels {fit})" for s, fit in slopes["fit_levels"].items()
           if isinstance(fit, str) and fit != default}
    panels = (("step_seconds", "step_slope", "CPU seconds per time step"),
              ("memory_mb", "memory_slope", "peak memory above the coarsest run (MB)"))
    for ax, (y, slope, ylabel) in zip(axes, panels):
        shown = levels.assign(**{y: levels[y].where(levels[y] > 0)})
        scheme_lines(ax, shown, "nV", y)
        ax.legend([f"{style(s)[0]}: {fix(slopes[slope].get(s), 2)}" + own.get(s, "")
                   for s in shown["scheme"].unique()],
                  title="slope", fontsize=7, title_fontsize=8, loc="upper left",
                  frameon=False)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_xlabel("unknowns $n$ (DDFV: F- and T-vertices)")
        ax.set_ylabel(ylabel)
        ax.grid(True, which="major", linewidth=0.5, alpha=0.5)
    fig.suptitle(f"Cost against size, shrinking sphere (slopes of $c\\,n^p$ fitted on levels "
                 f"{', '.join(str(lv) for lv in fit_levels)}; one core per job)", fontsize=10)
    return fig


def beyond_figures(levels, stability, series, time, space, beyond, t_final):
    """``name -> figure`` of the beyond study from its tables (DataFrames); the
    scaling study's figure is :func:`scaling_figure` (rule ``beyond_scaling``)."""
    monitored = list(dict.fromkeys([*beyond["schemes"], *beyond["long_time"]["schemes"]]))
    return {"levels": levels_figure(levels, t_final),
            "t_monitor": t_monitor_figure(series, stability, monitored),
            "time_convergence": time_figure(time),
            "space_convergence": space_figure(space)}
