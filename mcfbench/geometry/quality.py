"""Mesh-quality diagnostics of the diamond mesh along a flow (Section 3.2).

One row per time level ``n`` (``t = n tau``) and run; the columns
(:data:`COLUMNS`; the CSV ``results/diagnostics/{figure}.csv`` of the
pipeline adds a first column ``run``, the run's key in its experiment):

``family``
    ``"ddfv"`` (F- and T-vertices, every monitor) or ``"vertex"`` (the
    cotangent scheme and the other schemes on the mesh vertices only: the
    diamond monitors below are empty (NaN), the ``primal_*`` monitors,
    ``area`` and ``volume`` are those of the triangle mesh).

``t_bary_min``, ``t_bary_median``
    Each T-vertex is projected into the plane of its triangle and its
    barycentric coordinates taken (:func:`ddfv.geometry.t_barycentric`);
    per T-vertex the smallest of the three is kept (``1/3`` at the
    barycentre, ``< 0`` once the projection has left the triangle,
    Section 3.2). Reported: its minimum and median over all T-vertices.
``diamond_area_min_rel``
    Smallest diamond area ``chi(V^D) = J/2`` (2.8) divided by the mean
    diamond area: ``-> 0`` when a diamond cell collapses (Figs. 3.4, 3.6).
``angle_min_deg``
    Smallest angle, in degrees, of the triangles ``(F_a, F_b, T_t1)`` and
    ``(F_a, F_b, T_t2)`` into which the primal edge cuts each diamond cell
    (each primal triangle is cut into three by its T-vertex; these ``3 n_T``
    triangles are the faces of the diamond mesh drawn by
    :mod:`ddfv.render`). It goes to 0 when a T-vertex approaches an edge of
    its triangle; the angles of a triangle folded over (normal opposite to
    that of its primal triangle) count as negative, so the monitor stays
    below 0 while the diamond mesh is folded.
``area``, ``volume``
    Area and enclosed (signed) volume of that triangulated diamond-mesh
    surface; the volume is ``(1/6) sum det(A, B, C)`` over its oriented
    triangles, meaningful for closed surfaces only.
``worst_t``, ``worst_diamond``
    Where: the T-vertex with the smallest barycentric coordinate and the
    diamond with the smallest area (empty for ``vertex`` runs).
``primal_angle_min_deg``, ``primal_area_min_rel``, ``primal_flipped``, ``worst_triangle``
    The primal triangle mesh (the F-vertices; every scheme): smallest
    interior angle in degrees (:func:`mcfbench.geometry.metrics.min_angle`),
    smallest triangle area over the mean, number of triangles folded over
    against their neighbours (:func:`mcfbench.geometry.metrics.flipped_triangles`)
    and the triangle with the smallest area.

A ``ddfv`` row violates when a T-vertex has left its triangle or a
diamond cell collapsed; a ``vertex`` row when a triangle collapsed or
folded over (:func:`first_violation`).

Use :class:`MeshQuality` as an observer of
:func:`mcfbench.running.driver.simulate`, then :meth:`MeshQuality.frame`,
:func:`first_violation` and :func:`plot_quality`.
"""

import numpy as np
import pandas as pd

from ddfv.geometry import diamond_corners, diamond_geometry, t_barycentric
from ddfv.topology import diamond_mesh

#: relative diamond area below which a diamond cell counts as collapsed
COLLAPSE_AREA = 1e-8

COLUMNS = ("n", "t", "t_bary_min", "t_bary_median", "diamond_area_min_rel",
           "angle_min_deg", "area", "volume", "worst_t", "worst_diamond", "family",
           "primal_angle_min_deg", "primal_area_min_rel", "primal_flipped", "worst_triangle")

#: the monitors of the diamond mesh (empty for ``vertex`` runs)
DIAMOND_COLUMNS = ("t_bary_min", "t_bary_median", "diamond_area_min_rel", "angle_min_deg",
                   "worst_t", "worst_diamond")
_INTEGER_COLUMNS = ("worst_t", "worst_diamond", "primal_flipped", "worst_triangle")


def mesh_quality(mesh, F, T, geometry=None):
    """The monitors of one state of the diamond mesh (see module docstring).

    Parameters
    ----------
    mesh : DiamondMesh
    F : (n_f, 3) float array
    T : (n_t, 3) float array
    geometry : DiamondGeometry, optional
        Of ``(F, T)``; computed when not given.

    Returns
    -------
    dict
        The columns of :data:`COLUMNS` except ``n`` and ``t``
        (``family = "ddfv"``; the ``primal_*`` ones of the F-vertices).

    Examples
    --------
    >>> from ddfv.topology import diamond_mesh
    >>> from mcfbench.geometry.surfaces import icosphere
    >>> V, faces = icosphere(2)
    >>> T = V[faces].mean(axis=1)
    >>> q = mesh_quality(diamond_mesh(faces), V, T)
    >>> round(q["t_bary_min"], 6), round(q["t_bary_median"], 6)
    (0.333333, 0.333333)
    """
    g = diamond_geometry(mesh, F, T) if geometry is None else geometry
    bary = t_barycentric(F, T, mesh.faces).min(axis=1)
    bary = np.where(np.isfinite(bary), bary, -np.inf)  # degenerate triangle: violation
    half_j = 0.5 * g.J
    rel = half_j / half_j.mean()

    A, B, C = diamond_triangles(mesh, F, T)
    angle = _signed_smallest_angle(mesh, F, A, B, C)
    cross = _cross(B - A, C - A)
    area = 0.5 * float(np.sqrt(_dot(cross, cross)).sum())
    volume = float(_dot(A, _cross(B, C)).sum()) / 6.0
    return {
        "t_bary_min": float(bary.min()),
        "t_bary_median": float(np.median(bary)),
        "diamond_area_min_rel": float(rel.min()),
        "angle_min_deg": float(np.degrees(angle.min())),
        "area": area,
        "volume": volume,
        "worst_t": int(np.argmin(bary)),
        "worst_diamond": int(np.argmin(rel)),
        "family": "ddfv",
        **primal_quality(F, mesh.faces),
    }


def primal_quality(vertices, faces):
    """The ``primal_*`` monitors and ``worst_triangle`` of a triangle mesh.

    Returns
    -------
    dict
        ``primal_angle_min_deg``, ``primal_area_min_rel``,
        ``primal_flipped``, ``worst_triangle`` (see module docstring).

    Examples
    --------
    >>> from mcfbench.geometry.surfaces import icosphere
    >>> q = primal_quality(*icosphere(1))
    >>> round(q["primal_angle_min_deg"], 1), q["primal_flipped"]
    (55.6, 0)
    """
    from mcfbench.geometry.metrics import flipped_triangles, min_angle, triangle_areas

    V = np.asarray(vertices, dtype=float)
    areas = triangle_areas(V, faces)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = areas / areas.mean()
    finite = np.isfinite(V).all()
    return {
        "primal_angle_min_deg": min_angle(V, faces) if finite else float("nan"),
        "primal_area_min_rel": float(rel.min()) if finite else float("nan"),
        "primal_flipped": flipped_triangles(V, faces) if finite else 0,
        "worst_triangle": int(np.nanargmin(rel)) if finite else 0,
    }


def vertex_quality(vertices, faces):
    """The row of a state of a vertex scheme (``family = "vertex"``): the
    primal monitors, ``area`` and ``volume`` of the triangle mesh, NaN
    diamond monitors."""
    from mcfbench.geometry.metrics import area, volume

    row = {key: float("nan") for key in DIAMOND_COLUMNS}
    row.update(area=area(vertices, faces), volume=volume(vertices, faces), family="vertex")
    row.update(primal_quality(vertices, faces))
    return row


class MeshQuality:
    """Observer collecting the monitors at every time level.

    A DDFV flow (one with T-vertices, ``flow.T``) gets :func:`mesh_quality`,
    any other flow :func:`vertex_quality` of ``flow.vertices``,
    ``flow.faces``.

    Examples
    --------
    >>> from ddfv import Flow
    >>> from mcfbench.running.driver import simulate
    >>> from mcfbench.geometry.surfaces import icosphere
    >>> quality = MeshQuality()
    >>> _ = simulate(Flow(*icosphere(1), 0.01), 3, observers=[quality])
    >>> quality.frame()["n"].tolist()
    [0, 1, 2, 3]
    """

    def __init__(self):
        self.rows = []
        self._mesh = None

    def __call__(self, flow):
        row = {"n": int(flow.n), "t": float(flow.n * flow.tau)}
        if getattr(flow, "T", None) is not None:
            if self._mesh is None:
                self._mesh = diamond_mesh(flow.faces, len(flow.F))
            row.update(mesh_quality(self._mesh, flow.F, flow.T))
        else:
            row.update(vertex_quality(flow.vertices, flow.faces))
        self.rows.append(row)

    def frame(self):
        """pandas.DataFrame, one row per observed time level, :data:`COLUMNS`
        (the indices and counts as nullable integers: empty where undefined)."""
        df = pd.DataFrame(self.rows, columns=list(COLUMNS))
        return df.astype({key: "Int64" for key in _INTEGER_COLUMNS})


def first_violation(df, collapse_area=COLLAPSE_AREA):
    """First time level at which the mesh is no longer valid.

    A ``ddfv`` level (or one without a ``family`` column) is a violation
    when a T-vertex has left its triangle (``t_bary_min < 0``) or a diamond
    cell collapsed (``diamond_area_min_rel < collapse_area``); a
    ``vertex`` level when a triangle collapsed (``primal_area_min_rel <
    collapse_area``) or folded over (``primal_flipped > 0``). NaN monitors
    count too.

    Parameters
    ----------
    df : pandas.DataFrame
        From :meth:`MeshQuality.frame`.
    collapse_area : float

    Returns
    -------
    int or None
        The ``n`` of the first violating row, ``None`` if there is none.
    """
    bad = violations(df, collapse_area)
    return int(df.loc[bad, "n"].iloc[0]) if bad.any() else None


def violations(df, collapse_area=COLLAPSE_AREA):
    """(rows,) bool Series: the rows that violate (see :func:`first_violation`)."""
    vertex = _is_vertex(df)
    diamond = ~(df["t_bary_min"] >= 0) | ~(df["diamond_area_min_rel"] >= collapse_area)
    if not vertex.any():
        return diamond
    primal = ~(df["primal_area_min_rel"] >= collapse_area) \
        | (df["primal_flipped"].fillna(0).astype(float) > 0)
    return pd.Series(np.where(vertex, primal, diamond), index=df.index)


def describe_violation(df, collapse_area=COLLAPSE_AREA):
    """One sentence on the first violation, or ``""`` when there is none."""
    bad = violations(df, collapse_area)
    if not bad.any():
        return ""
    row = df.loc[bad].iloc[0]
    what = []
    if _is_vertex(df.loc[bad].iloc[:1]).iloc[0]:
        if not row["primal_area_min_rel"] >= collapse_area:
            what.append(f"triangle {_index(row['worst_triangle'])} collapsed "
                        f"(relative area {row['primal_area_min_rel']:.3g})")
        if row["primal_flipped"] > 0:
            what.append(f"{int(row['primal_flipped'])} triangle(s) folded over")
    else:
        if not row["t_bary_min"] >= 0:
            what.append(f"T-vertex {_index(row['worst_t'])} left its triangle "
                        f"(barycentric {row['t_bary_min']:.3g})")
        if not row["diamond_area_min_rel"] >= collapse_area:
            what.append(f"diamond {_index(row['worst_diamond'])} collapsed "
                        f"(relative area {row['diamond_area_min_rel']:.3g})")
    return f"step {int(row['n'])} (t = {row['t']:.6g}): " + " and ".join(what)


def _is_vertex(df):
    """(rows,) bool Series: the row is of a vertex scheme (no T-vertices)."""
    if "family" not in df:
        return pd.Series(False, index=df.index)
    return df["family"].eq("vertex").fillna(False).astype(bool)


def _index(value):
    return "?" if pd.isna(value) else int(value)


def diamond_triangles(mesh, F, T):
    """Corners of the triangles ``(F_a, F_b, T_t1)`` and ``(F_b, F_a, T_t2)``.

    The two halves of every diamond cell on either side of its primal edge,
    oriented like the primal triangles; a boundary diamond has only the
    first. Rows ``0 ... n_d - 1`` are the ``T_t1`` halves of all diamonds,
    the rest the ``T_t2`` halves of the inner diamonds.

    Returns
    -------
    A, B, C : (3, n_d + n_inner) float arrays
    """
    Fa, Fb, T1, T2 = diamond_corners(mesh, F, T)
    inner = ~mesh.boundary
    A = np.concatenate([Fa, Fb[:, inner]], axis=1)
    B = np.concatenate([Fb, Fa[:, inner]], axis=1)
    C = np.concatenate([T1, T2[:, inner]], axis=1)
    return A, B, C


def diamond_min_angles(mesh, F, T):
    """(n_d,) smallest angle (radians) of the two halves of each diamond cell.

    Negative for a half folded over (see ``angle_min_deg`` in the module
    docstring).
    """
    A, B, C = diamond_triangles(mesh, F, T)
    angle = _signed_smallest_angle(mesh, F, A, B, C)
    n_d = len(mesh.diamonds)
    out = angle[:n_d].copy()
    inner = np.flatnonzero(~mesh.boundary)
    out[inner] = np.minimum(out[inner], angle[n_d:])
    return out


#: linear range of the symlog axis of the T barycentric coordinate
SYMLOG_LINEAR = 0.35


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


def _family(df):
    return "vertex" if _is_vertex(df).all() else "ddfv"


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

    bars(ax_b, y, [r["t_bary_min"] for r in rows], diamond_c, ".4f", "smallest")
    ax_b.plot([r["t_bary_median"] for r in rows], y, "k|", ms=14, label="median")
    ax_b.axvline(1 / 3, color="0.5", lw=0.8, ls="--")
    known = [float(r["t_bary_min"]) for r in rows if not pd.isna(r["t_bary_min"])]
    ax_b.set_xlim(min([0.0, *known]), 0.5)
    ax_b.set_xlabel("T-vertex barycentric coordinate\n(1/3: barycentre, < 0: outside)")
    bars(ax_g, y + h / 2, [r["angle_min_deg"] for r in rows], diamond_c, ".1f",
         "diamond mesh (F, F, T)")
    bars(ax_g, y - h / 2, [r["primal_angle_min_deg"] for r in rows], primal_c, ".1f",
         "primal triangles")
    ax_g.set_xlim(0, 75)
    ax_g.set_xlabel("smallest angle [deg]")
    bars(ax_a, y + h / 2, [r["diamond_area_min_rel"] for r in rows], diamond_c, ".3f",
         "diamond cells")
    bars(ax_a, y - h / 2, [r["primal_area_min_rel"] for r in rows], primal_c, ".3f",
         "primal triangles")
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
    ddfv = {name: df for name, df in frames.items() if _family(df) == "ddfv"}
    for k, (name, df) in enumerate(frames.items()):
        color = f"C{k}"
        n = df["n"].to_numpy()
        family = _family(df)
        if family == "ddfv":
            ax_b.plot(n, df["t_bary_min"].astype(float), color=color)
            ax_b.plot(n, df["t_bary_median"].astype(float), color=color, ls="--")
            ax_g.plot(n, df["angle_min_deg"].astype(float), color=color)
            ax_a.semilogy(n, df["diamond_area_min_rel"].astype(float).clip(lower=1e-16),
                          color=color)
        ax_g.plot(n, df["primal_angle_min_deg"].astype(float), color=color, ls="--")
        ax_a.semilogy(n, df["primal_area_min_rel"].astype(float).clip(lower=1e-16),
                      color=color, ls="--")
        a0 = df["area"].iloc[0]
        ax_v.plot(n, df["area"] / a0 if a0 else df["area"], color=color)
        bad = first_violation(df)
        label = name + (f": first violation at n = {bad}" if bad is not None
                        else ": no violation")
        run_handles.append(Line2D([], [], color=color, lw=2, label=label))
        mesh = "diamond and primal mesh" if family == "ddfv" else "primal mesh"
        described.append(f"{name} ({mesh})")
        if bad is not None:
            for ax in axes.ravel():
                ax.axvline(bad, color=color, ls=":", lw=1.2)
    # (a) T barycentric coordinate
    ax_b.axhline(0.0, color="0.3", lw=0.9)
    ax_b.axhline(1.0 / 3.0, color="0.75", lw=0.8)
    if ddfv:
        low = min(float(df["t_bary_min"].astype(float).min()) for df in ddfv.values())
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
    styles = ([Line2D([], [], color="0.3", label="diamond mesh")] if ddfv else []) \
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


def _signed_smallest_angle(mesh, F, A, B, C):
    """:func:`_smallest_angle`, negated where the triangle's normal opposes
    the normal of the primal triangle it lies in."""
    inner = ~mesh.boundary
    tri = np.r_[mesh.diamonds[:, 2], mesh.diamonds[inner, 3]]
    p0, p1, p2 = (np.take(F.T, mesh.faces[tri, k], axis=1) for k in range(3))
    folded = _dot(_cross(p1 - p0, p2 - p0), _cross(B - A, C - A)) < 0
    angle = _smallest_angle(A, B, C)
    return np.where(folded, -angle, angle)


def _smallest_angle(A, B, C):
    """(m,) smallest interior angle of the triangles with (3, m) corners A, B, C."""
    ab, bc, ca = B - A, C - B, A - C
    cr = _cross(ab, -ca)
    twice_area = np.sqrt(_dot(cr, cr))
    # angle at a corner = atan2(|x cross y|, x . y): |x cross y| = 2 area
    at_a = np.arctan2(twice_area, -_dot(ab, ca))
    at_b = np.arctan2(twice_area, -_dot(bc, ab))
    at_c = np.arctan2(twice_area, -_dot(ca, bc))
    return np.minimum(np.minimum(at_a, at_b), at_c)


def _cross(x, y):
    return np.stack([x[1] * y[2] - x[2] * y[1],
                     x[2] * y[0] - x[0] * y[2],
                     x[0] * y[1] - x[1] * y[0]])


def _dot(x, y):
    return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]
