"""Figures of the study beyond Table 3.1, from its tables.

Called by rule ``beyond_figures`` (workflow/rules/beyond.smk). Writes, under
``results/beyond/figures/`` (PNG and PDF):

``levels``
    top: L2 error (3.2) against h for every scheme (as the convergence
    figure, :func:`plot_convergence.draw`), the published values, crosses
    for runs that broke down; bottom: ours over the published L2 error for
    the DDFV variants (levels of Table 3.1).
``t_monitor``
    the T monitor against time, one panel per DDFV variant, one line per
    level, the long run dashed; plotted as the distance ``1/3 - monitor`` of
    the worst T-vertex from the barycentre of its triangle on a log scale,
    so that the slow drift and the breakdown (monitor -> large negative)
    both show; crosses where a run broke down.
``time_convergence``, ``space_convergence``
    error against tau (fixed mesh, slope 1) and against h (fixed tiny tau,
    slope 2).
"""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.ticker import FixedLocator, NullFormatter  # noqa: E402

from run_records import setup_logging  # noqa: E402  (first: sys.path)
from plot_convergence import draw, scheme_lines, slope_guide, styles  # noqa: E402

EDGE = 1.0 / 3.0   # 1/3 - monitor at which a T-vertex reaches an edge of its triangle
SAVE = {"png": {"dpi": 200, "metadata": {"Software": None}},
        "pdf": {"metadata": {"CreationDate": None, "Creator": None, "Producer": None}}}


# variant -> what it is, for the legends (the scheme name comes first)
VARIANTS = {"paper": "as published", "chord": r"chord $|\gamma|$",
            "eliminate": "elimination (3.6)", "barycentric": "cotangent, libigl",
            "voronoi": "cotangent, Voronoi mass"}


def legend_style(table):
    """``scheme -> (label, colour, marker)``: the scheme's name and its variant."""
    variants = table.drop_duplicates("scheme").set_index("scheme")["variant"]
    return {s: (f"{s} ({VARIANTS.get(variants[s], variants[s])})", colour, marker)
            for s, (_, colour, marker) in styles(list(variants.index)).items()}


def tex_number(x):
    """``9.765625e-06`` as mathtext ``9.77 \\cdot 10^{-6}`` (from 1e-3 up: ``%g``)."""
    if x >= 1e-3:
        return f"{x:g}"
    mantissa, exponent = f"{x:.2e}".split("e")
    return f"{float(mantissa):g} \\cdot 10^{{{int(exponent)}}}"


def plot_levels(table, t_final):
    """L2 error per level for every scheme, and the ratio to the paper."""
    fig, (ax, bottom) = plt.subplots(2, 1, figsize=(6.0, 6.4), sharex=True,
                                     height_ratios=[3, 1.3], layout="constrained")
    style = legend_style(table)
    draw(ax, table, t_final, style)
    ax.set_xlabel("")
    ax.set_title("L2 error per level: DDFV variants and the cotangent scheme", fontsize=10)
    ratio = table[np.isfinite(table["l2_ratio"])]
    for scheme in ratio["scheme"].unique():
        rows = ratio[ratio["scheme"] == scheme].sort_values("h")
        label, colour, marker = style[scheme]
        bottom.plot(rows["h"], rows["l2_ratio"], marker=marker, color=colour, markersize=5,
                    linewidth=1.2, label=label)
    bottom.axhline(1.0, color="black", linewidth=0.8, linestyle=":")
    bottom.set_ylabel("L2 ours / paper", fontsize=9)
    bottom.set_xlabel(r"mesh size $h$ (mean edge length)")
    bottom.grid(True, linewidth=0.5, alpha=0.5)
    bottom.xaxis.set_minor_formatter(NullFormatter())
    return fig


def plot_t_monitor(series, stability, schemes, long_level):
    """The T monitor against time, per variant and level (log of 1/3 - monitor)."""
    schemes = [s for s in schemes if s in set(series["scheme"])]
    fig, axes = plt.subplots(1, len(schemes), figsize=(3.6 * len(schemes) + 0.6, 4.2),
                             sharey=True, squeeze=False, layout="constrained")
    levels = sorted(series.loc[series["study"] == "levels", "level"].unique())
    colours = plt.get_cmap("viridis")(np.linspace(0.0, 0.9, max(len(levels), 1)))
    colour = dict(zip(levels, colours))
    t_max = series["t"].max()
    deficit = EDGE - series["t_monitor"].to_numpy()
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
                    ax.plot(run["t"], EDGE - run["t_monitor"], color=colour.get(level, "k"),
                            linewidth=1.5, label=f"level {level}")
                else:
                    ax.plot(run["t"], EDGE - run["t_monitor"], color="black", linewidth=1.1,
                            dashes=(4, 2),
                            label=f"level {level} to t = {run['t_final'].iloc[0]:g}")
        failed = stability[(stability["scheme"] == scheme) & (stability["status"] != "ok")]
        for r in failed.itertuples():
            y = EDGE - r.t_monitor_end
            ax.plot([r.t_reached], [y], marker="X", markersize=9, color="tab:red",
                    markeredgecolor="black", markeredgewidth=0.6, linestyle="none", zorder=5)
            right = r.t_reached < 0.5 * t_max
            what = "long run" if r.study == "long_time" else f"level {r.level}"
            ax.annotate(f"{what} breaks down at t = {r.t_failed:.4g}\n"
                        f"(monitor {r.t_monitor_end:.3g} one step before)", (r.t_reached, y),
                        xytext=(8, 4) if right else (-8, -4), textcoords="offset points",
                        ha="left" if right else "right", va="bottom" if right else "top",
                        fontsize=7)
        ok = stability[(stability["scheme"] == scheme) & (stability["status"] == "ok")]
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
        ax.set_title(scheme, fontsize=10)
        ax.set_xlabel("time t")
        ax.grid(True, which="major", linewidth=0.5, alpha=0.5)
    axes[0][0].set_ylabel("1/3 $-$ T monitor  (log scale)")
    fig.suptitle("T monitor = smallest barycentric coordinate of any T-vertex projected into "
                 "its triangle (1/3 at the barycentre, < 0 outside)", fontsize=9)
    handles, labels = axes[0][-1].get_legend_handles_labels()
    order = sorted(range(len(labels)), key=lambda i: (labels[i].count("to t"), labels[i]))
    axes[0][-1].legend([handles[i] for i in order], [labels[i] for i in order], fontsize=7,
                       loc="center right", frameon=False)
    return fig


def plot_time(table):
    """Error at t_f against tau on a fixed mesh, one line per scheme, slope 1."""
    fig, ax = plt.subplots(figsize=(5.2, 4.0), layout="constrained")
    ok = scheme_lines(ax, table, "tau", "error", legend_style(table))
    slope_guide(ax, ok, "tau", "error", 1, r"slope 1 ($\propto \tau$)")
    ax.set_xscale("log")
    ax.set_yscale("log")
    taus = np.sort(table["tau"].dropna().unique())
    ax.xaxis.set_major_locator(FixedLocator(taus))
    ax.xaxis.set_major_formatter(plt.FixedFormatter([f"{t:g}" for t in taus]))
    ax.xaxis.set_minor_formatter(NullFormatter())
    ax.tick_params(axis="x", labelsize=7)
    first = table.iloc[0]
    ax.set_xlabel(r"time step $\tau$")
    ax.set_ylabel(r"error at $t_f$ against a fine-$\tau$ reference")
    ax.text(0.97, 0.04, f"icosphere level {first.level} (fixed mesh), "
            f"$t_f = {first.t_final:g}$\nreference $\\tau = {tex_number(first.reference_tau)}$",
            transform=ax.transAxes, ha="right", va="bottom", fontsize=8)
    ax.grid(True, which="major", linewidth=0.5, alpha=0.5)
    ax.legend(fontsize=8, loc="upper left", frameon=False)
    ax.set_title("Convergence in time", fontsize=10)
    return fig


def plot_space(table):
    """Error (3.2) against h with one tiny tau, slope 2 (as the convergence figure)."""
    fig, ax = plt.subplots(figsize=(5.2, 4.0), layout="constrained")
    first = table.iloc[0]
    draw(ax, table.assign(paper_l2_error=np.nan), first.t_final, legend_style(table),
         note=f"shrinking unit sphere\n$\\tau = {tex_number(first.tau)}$ on every level, "
              f"$t_f = {first.t_final:g}$")
    ax.set_title("Convergence in space", fontsize=10)
    return fig


def save(fig, paths):
    for ext, path in paths.items():
        fig.savefig(path, **SAVE[ext])
    plt.close(fig)


def main(inputs, beyond, t_final, outputs, log_file):
    log = setup_logging(log_file)
    levels = pd.read_csv(inputs["levels"])
    stability = pd.read_csv(inputs["stability"])
    series = pd.read_csv(inputs["t_monitor"])
    ddfv = [s for s in beyond["schemes"] if s in set(stability["scheme"])]
    ddfv += [s for s in beyond["long_time"]["schemes"] if s not in ddfv]
    figures = {
        "levels": plot_levels(levels, t_final),
        "t_monitor": plot_t_monitor(series, stability, ddfv, beyond["long_time"]["level"]),
        "time_convergence": plot_time(pd.read_csv(inputs["time"])),
        "space_convergence": plot_space(pd.read_csv(inputs["space"])),
    }
    for name, fig in figures.items():
        save(fig, {ext: outputs[f"{name}_{ext}"] for ext in ("png", "pdf")})
        log.info("wrote %s", outputs[f"{name}_png"])


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main({key: str(path) for key, path in sm.input.items()}, dict(sm.params.beyond),
         sm.params.t_final, {key: str(path) for key, path in sm.output.items()}, sm.log[0])
