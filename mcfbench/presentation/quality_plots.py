"""Plots of the mesh-quality diagnostics along a flow (:mod:`mcfbench.geometry.quality`):
the smallest angles, the T monitor and the flipped cells against the step."""

import numpy as np
import pandas as pd

from mcfbench.geometry.quality import (
    COLLAPSE_AREA,
    first_violation,
    vertex_rows,
)

SYMLOG_LINEAR = 0.35
"""Linear range of the symlog axis of the T monitor."""


def plot_quality(frames, title="", marks=()):
    """Plot the monitors of one or more runs.

    Parameters
    ----------
    frames : dict
        Legend label -> DataFrame of :meth:`MeshQuality.frame` (any family).
    title : str
        First line of the title; a second line says what is plotted.
    marks : sequence of int
        Time levels to mark (e.g. those shown in a figure).

    Returns
    -------
    matplotlib.figure.Figure
        With a single time level in every run (no evolution, e.g. Fig. 3.1)
        a bar chart of the quality of each mesh (:func:`plot_levels`);
        otherwise four panels against the time level (:func:`plot_series`).
        Without any row, a figure that says so.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    frames = {name: df for name, df in frames.items() if df is not None and len(df)}
    if not frames:
        fig, ax = plt.subplots(figsize=(6, 2))
        ax.set_axis_off()
        ax.text(0.5, 0.5, "no mesh-quality data: no run was computed", ha="center",
                va="center", transform=ax.transAxes)
        if title:
            fig.suptitle(title)
        return fig
    if all(df["n"].nunique() == 1 for df in frames.values()):
        return plot_levels(frames, title)
    return plot_series(frames, title, marks)


def _with_t_vertices(df):
    """Whether the rows monitor T-vertices and a diamond mesh (DDFV's), not only
    the primal triangles (:func:`mcfbench.geometry.quality.vertex_rows`)."""
    return not vertex_rows(df).all()


def plot_levels(frames, title=""):
    """Bar chart of the quality of meshes without time evolution (one row each).

    Three panels, one bar group per run: the smallest barycentric
    coordinate of the T-vertices (median as a tick), the smallest angle
    and the smallest area over the mean, each of the diamond mesh and of
    the primal triangles. Values are printed on the bars.
    """
    import matplotlib.pyplot as plt

    names = list(frames)
    rows = [frames[name].iloc[0] for name in names]
    y = np.arange(len(names))[::-1].astype(float)
    fig, axes = plt.subplots(1, 3, figsize=(11, 1.6 + 0.55 * len(names)), sharey=True)
    ax_b, ax_g, ax_a = axes
    h = 0.36
    diamond_c, primal_c = "#d62020", "#1f4fd8"      # the edge colours of the figures

    def bars(ax, yy, values, color, fmt, label):
        values = np.array([np.nan if pd.isna(v) else float(v) for v in values])
        ax.barh(yy, np.nan_to_num(values), height=h, color=color, alpha=0.75, label=label)
        for yi, v in zip(yy, values):
            ax.text(0 if np.isnan(v) else v, yi, " n/a" if np.isnan(v) else f" {v:{fmt}}",
                    va="center", ha="left", fontsize=8)

    def diamond_and_primal(ax, diamond, primal, fmt, label):
        """The diamond mesh's bars (column ``diamond``) above the primal triangles'."""
        bars(ax, y + h / 2, [r[diamond] for r in rows], diamond_c, fmt, label)
        bars(ax, y - h / 2, [r[primal] for r in rows], primal_c, fmt, "primal triangles")

    bars(ax_b, y, [r["t_bary_min"] for r in rows], diamond_c, ".4f", "smallest")
    ax_b.plot([r["t_bary_median"] for r in rows], y, "k|", ms=14, label="median")
    ax_b.axvline(1 / 3, color="0.5", lw=0.8, ls="--")
    known = [float(r["t_bary_min"]) for r in rows if not pd.isna(r["t_bary_min"])]
    ax_b.set_xlim(min([0.0, *known]), 0.5)
    ax_b.set_xlabel("T-vertex barycentric coordinate\n(1/3: barycentre, < 0: outside)")
    diamond_and_primal(ax_g, "angle_min_deg", "min_angle", ".1f", "diamond mesh (F, F, T)")
    ax_g.set_xlim(0, 75)
    ax_g.set_xlabel("smallest angle [deg]")
    diamond_and_primal(ax_a, "diamond_area_min_rel", "primal_area_min_rel", ".3f",
                       "diamond cells")
    ax_a.set_xlim(0, 1.3)
    ax_a.set_xlabel("smallest area / mean area")
    ax_b.set_yticks(y, names)
    ax_b.set_ylim(-0.6, len(names) + 0.15)        # room for the legends above the bars
    for ax in axes:
        ax.grid(axis="x", alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", ncol=2, framealpha=0.9)
    steps = sorted({int(frames[n]["n"].iloc[0]) for n in names})
    what = (f"mesh quality at n = {', '.join(map(str, steps))} only: these meshes are not "
            "evolved (no time steps), so there is no time series")
    fig.suptitle(f"{title}\n{what}" if title else what, fontsize=10)
    fig.tight_layout()
    return fig


def plot_series(frames, title="", marks=()):
    """The monitors of one or more runs against the time level.

    Four panels: (a) the T-vertices' barycentric coordinates, smallest
    (solid) and median (dashed), DDFV runs only, on a symmetric-log axis
    when a T-vertex goes far out (linear in ``[-0.35, 0.35]``), with 0 ("a
    T-vertex leaves its triangle") marked; (b) the smallest angle and
    (c) the smallest area over the mean, of the diamond mesh (solid, DDFV)
    and of the primal triangles (dashed, every run); (d) the surface area
    relative to ``n = 0``. The first violation of each run
    (:func:`first_violation`) is a dotted line in its colour, the time
    levels ``marks`` light grey lines.
    """
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    fig, axes = plt.subplots(2, 2, figsize=(10, 6.6), sharex=True)
    (ax_b, ax_g), (ax_a, ax_v) = axes
    run_handles, described = [], []
    with_t = {name: df for name, df in frames.items() if _with_t_vertices(df)}
    for k, (name, df) in enumerate(frames.items()):
        color = f"C{k}"
        n = df["n"].to_numpy()
        if name in with_t:
            ax_b.plot(n, df["t_bary_min"].astype(float), color=color)
            ax_b.plot(n, df["t_bary_median"].astype(float), color=color, ls="--")
            ax_g.plot(n, df["angle_min_deg"].astype(float), color=color)
            ax_a.semilogy(n, df["diamond_area_min_rel"].astype(float).clip(lower=1e-16),
                          color=color)
        ax_g.plot(n, df["min_angle"].astype(float), color=color, ls="--")
        ax_a.semilogy(n, df["primal_area_min_rel"].astype(float).clip(lower=1e-16),
                      color=color, ls="--")
        a0 = df["area"].iloc[0]
        ax_v.plot(n, df["area"] / a0 if a0 else df["area"], color=color)
        bad = first_violation(df)
        label = name + (f": first violation at n = {bad}" if bad is not None
                        else ": no violation")
        run_handles.append(Line2D([], [], color=color, lw=2, label=label))
        mesh = "diamond and primal mesh" if name in with_t else "primal mesh"
        described.append(f"{name} ({mesh})")
        if bad is not None:
            for ax in axes.ravel():
                ax.axvline(bad, color=color, ls=":", lw=1.2)
    # (a) T barycentric coordinate
    ax_b.axhline(0.0, color="0.3", lw=0.9)
    ax_b.axhline(1.0 / 3.0, color="0.75", lw=0.8)
    if with_t:
        low = min(float(df["t_bary_min"].astype(float).min()) for df in with_t.values())
        if low < -SYMLOG_LINEAR:
            ax_b.set_yscale("symlog", linthresh=SYMLOG_LINEAR, linscale=3.0)
            ax_b.set_ylim(1.4 * low, 0.55)
            ticks = [1 / 3, 0.2, 0.0, -0.2] + [-10.0 ** e for e in range(0, 4)
                                                if -10.0 ** e > 1.4 * low]
            ax_b.set_yticks(ticks, ["1/3", "0.2", "0", "-0.2"] + [
                f"{t:g}" for t in ticks[4:]])
        else:
            ax_b.set_ylim(min(low, 0.0) - 0.03, 0.37)
        ax_b.text(0.5, 0.0, "0: a T-vertex leaves its triangle", color="0.2", fontsize=7,
                  va="bottom", ha="center", transform=ax_b.get_yaxis_transform())
        ax_b.text(0.5, 1 / 3, "1/3: barycentre", color="0.45", fontsize=7, va="bottom",
                  ha="center", transform=ax_b.get_yaxis_transform())
        ax_b.legend(handles=[Line2D([], [], color="0.3", label="smallest"),
                             Line2D([], [], color="0.3", ls="--", label="median")],
                    fontsize=7, loc="lower left", title="over the T-vertices",
                    title_fontsize=7)
    else:
        ax_b.text(0.5, 0.5, "no T-vertices in these runs", ha="center", va="center",
                  transform=ax_b.transAxes, color="0.4")
    ax_b.set_ylabel("T-vertex barycentric coordinate")
    ax_b.set_title("(a) T-vertices in their triangles (DDFV)", fontsize=9)
    # (b) angles, (c) areas
    styles = ([Line2D([], [], color="0.3", label="diamond mesh")] if with_t else []) \
        + [Line2D([], [], color="0.3", ls="--", label="primal triangles")]
    ax_g.axhline(0.0, color="0.5", lw=0.8)
    ax_g.set_ylabel("smallest angle [deg]\n(< 0: folded over)")
    ax_g.set_title("(b) smallest angle", fontsize=9)
    ax_g.legend(handles=styles, fontsize=7, loc="lower left")
    smallest = min(min(float(df[c].astype(float).min()) for c in
                       ("diamond_area_min_rel", "primal_area_min_rel") if df[c].notna().any())
                   for df in frames.values())
    if smallest < 1e-3:
        ax_a.axhline(COLLAPSE_AREA, color="0.5", lw=0.8)
    else:
        ax_a.set_ylim(bottom=min(0.3 * smallest, 1e-2), top=2.0)
    ax_a.set_ylabel("smallest area / mean area")
    ax_a.set_title("(c) smallest cell: diamond cell or primal triangle", fontsize=9)
    ax_a.legend(handles=styles, fontsize=7, loc="lower left")
    ax_v.set_ylabel("surface area / area at n = 0")
    ax_v.set_title("(d) surface area (mean curvature flow decreases it)", fontsize=9)
    for ax in axes.ravel():
        for m in marks:
            ax.axvline(m, color="0.85", lw=0.8, zorder=0)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time step n")
    extra = []
    if any(first_violation(df) is not None for df in frames.values()):
        extra.append(Line2D([], [], color="0.3", ls=":", lw=1.2, label="first violation"))
    if marks:
        extra.append(Line2D([], [], color="0.8", lw=1.5, label="time levels of the figure"))
    fig.tight_layout(rect=(0, 0, 1, 0.89))
    what = "mesh quality per time step: " + ", ".join(described)
    fig.suptitle(f"{title}\n{what}" if title else what, fontsize=10, y=0.995)
    fig.legend(handles=run_handles + extra, loc="lower center", ncol=min(4, len(
        run_handles) + len(extra)), fontsize=8, frameon=False, bbox_to_anchor=(0.5, 0.885))
    return fig


#: linear range of the symlog axis of the T barycentric coordinate
