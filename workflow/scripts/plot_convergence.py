"""Convergence figure: space-time L2 error against the mesh size h (log-log).

Called by rule ``convergence_figure`` (workflow/rules/convergence.smk) with
``results/tables/convergence.csv``; one line per scheme, the published DDFV
errors of Table 3.1 as open markers, and a slope-2 reference line. A run
that broke down has no error: it is marked by a cross at the bottom of the
axes, at its mesh size, in the colour of its scheme. :func:`draw` draws
into a given axes (used by workflow/scripts/beyond_plots.py).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FixedFormatter, FixedLocator, NullFormatter  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from run_records import setup_logging  # noqa: E402

STYLE = {  # scheme -> label, colour, marker
    "ddfv": ("DDFV (ours)", "tab:blue", "o"),
    "ddfv-chord": (r"DDFV, chord $|\gamma|$ (ours)", "tab:green", "D"),
    "ddfv-eliminate": ("DDFV, elimination (3.6) (ours)", "tab:purple", "v"),
    "cotan": ("cotangent, libigl (ours)", "tab:orange", "s"),
}
OTHER_COLOURS = ["tab:red", "tab:brown", "tab:pink", "tab:olive"]


def styles(schemes):
    """``scheme -> (label, colour, marker)``: :data:`STYLE`, others in turn."""
    others = iter(OTHER_COLOURS)
    return {s: STYLE.get(s, (s, next(others, "k"), "^")) for s in schemes}


def plot(table, t_final):
    """The figure of ``table`` (the convergence CSV as a DataFrame)."""
    fig, ax = plt.subplots(figsize=(5.2, 4.0), layout="constrained")
    draw(ax, table, t_final)
    return fig


def draw(ax, table, t_final, style=None, note=None):
    """Draw the convergence plot of ``table`` into ``ax``.

    ``style`` maps schemes to ``(label, colour, marker)`` (default
    :func:`styles`); ``note`` replaces the text in the lower right corner
    (the experiment: shrinking sphere, ``tau ~ h^2``, ``t_f``).
    """
    style = style or styles(table["scheme"].unique())
    ok = scheme_lines(ax, table, "h", "l2_error", style)
    failed = table[table["status"] != "ok"]
    for i, r in enumerate(failed.itertuples()):
        ax.plot([r.h], [0.03 + 0.05 * (i % 3)], linestyle="none", marker="x",
                markersize=8, markeredgewidth=2, color=style[r.scheme][1],
                transform=ax.get_xaxis_transform(), clip_on=False,
                label="broke down (no error)" if i == 0 else None)
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


def scheme_lines(ax, table, x, y, style):
    """One line ``y`` against ``x`` per scheme, through its finished rows.

    Returns the finished rows (status ``ok``, finite ``y``).
    """
    ok = table[(table["status"] == "ok") & np.isfinite(table[y])]
    for scheme in table["scheme"].unique():
        rows = ok[ok["scheme"] == scheme].sort_values(x)
        label, colour, marker = style[scheme]
        ax.plot(rows[x], rows[y], marker=marker, color=colour, label=label,
                markersize=5, linewidth=1.5)
    return ok


def slope_guide(ax, ok, x, y, order, label):
    """A dashed ``x**order`` guide through half the smallest ``y`` at the smallest ``x``."""
    if len(ok):
        xs = np.array([ok[x].min(), ok[x].max()])
        smallest = ok[ok[x] == ok[x].min()][y].min()
        ax.plot(xs, 0.5 * smallest * (xs / xs[0]) ** order, linestyle="--", color="0.5",
                linewidth=1.0, label=label)


def main(csv, t_final, png, pdf, log_file):
    log = setup_logging(log_file)
    fig = plot(pd.read_csv(csv), t_final)
    fig.savefig(png, dpi=200, metadata={"Software": None})
    fig.savefig(pdf, metadata={"CreationDate": None, "Creator": None, "Producer": None})
    plt.close(fig)
    log.info("wrote %s, %s", png, pdf)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(sm.input.csv, sm.params.t_final, sm.output.png, sm.output.pdf, sm.log[0])
