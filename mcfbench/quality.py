"""Mesh-quality diagnostics of the diamond mesh along a flow (Section 3.2).

The monitors, per time level ``n``:

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
    diamond with the smallest area.

Use :class:`MeshQuality` as the ``observer`` of :func:`ddfv.simulate`,
then :meth:`MeshQuality.frame` and :func:`first_violation`.
"""

import numpy as np
import pandas as pd

from ddfv.geometry import diamond_corners, diamond_geometry, t_barycentric

#: relative diamond area below which a diamond cell counts as collapsed
COLLAPSE_AREA = 1e-8

COLUMNS = ("n", "t", "t_bary_min", "t_bary_median", "diamond_area_min_rel",
           "angle_min_deg", "area", "volume", "worst_t", "worst_diamond")


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
        The columns of :data:`COLUMNS` except ``n`` and ``t``.

    Examples
    --------
    >>> from ddfv import icosphere, diamond_mesh
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
    }


class MeshQuality:
    """Observer collecting :func:`mesh_quality` at every time level.

    Examples
    --------
    >>> from ddfv import icosphere, simulate
    >>> quality = MeshQuality()
    >>> _ = simulate(*icosphere(1), 0.01, 3, observer=quality)
    >>> quality.frame()["n"].tolist()
    [0, 1, 2, 3]
    """

    def __init__(self):
        self.rows = []

    def __call__(self, flow):
        row = {"n": int(flow.n), "t": float(flow.n * flow.tau)}
        row.update(mesh_quality(flow.mesh, flow.F, flow.T, flow.geometry))
        self.rows.append(row)

    def frame(self):
        """pandas.DataFrame, one row per observed time level, :data:`COLUMNS`."""
        return pd.DataFrame(self.rows, columns=list(COLUMNS))


def first_violation(df, collapse_area=COLLAPSE_AREA):
    """First time level at which the diamond mesh is no longer valid.

    A level is a violation when a T-vertex has left its triangle
    (``t_bary_min < 0``) or a diamond cell collapsed
    (``diamond_area_min_rel < collapse_area``); NaN monitors count too.

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
    return ~(df["t_bary_min"] >= 0) | ~(df["diamond_area_min_rel"] >= collapse_area)


def describe_violation(df, collapse_area=COLLAPSE_AREA):
    """One sentence on the first violation, or ``""`` when there is none."""
    bad = violations(df, collapse_area)
    if not bad.any():
        return ""
    row = df.loc[bad].iloc[0]
    what = []
    if not row["t_bary_min"] >= 0:
        what.append(f"T-vertex {int(row['worst_t'])} left its triangle "
                    f"(barycentric {row['t_bary_min']:.3g})")
    if not row["diamond_area_min_rel"] >= collapse_area:
        what.append(f"diamond {int(row['worst_diamond'])} collapsed "
                    f"(relative area {row['diamond_area_min_rel']:.3g})")
    return f"step {int(row['n'])} (t = {row['t']:.6g}): " + " and ".join(what)


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


def plot_quality(frames, title="", marks=()):
    """Plot the monitors of one or more runs against the time level.

    Parameters
    ----------
    frames : dict
        Legend label -> DataFrame of :meth:`MeshQuality.frame`.
    title : str
    marks : sequence of int
        Time levels to mark (e.g. those shown in a figure).

    Returns
    -------
    matplotlib.figure.Figure
        Four panels: T barycentric coordinates (min solid, median dashed),
        relative smallest diamond area (log), smallest angle, and the
        enclosed volume relative to ``n = 0``. The first violation
        (:func:`first_violation`) of each run is marked by a dotted line.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(9, 5.6), sharex=True)
    (ax_b, ax_a), (ax_g, ax_v) = axes
    for k, (name, df) in enumerate(frames.items()):
        color = f"C{k}"
        n = df["n"].to_numpy()
        ax_b.plot(n, df["t_bary_min"], color=color, label=f"{name}: min")
        ax_b.plot(n, df["t_bary_median"], color=color, ls="--", label=f"{name}: median")
        ax_a.semilogy(n, df["diamond_area_min_rel"].clip(lower=1e-16), color=color, label=name)
        ax_g.plot(n, df["angle_min_deg"], color=color, label=name)
        v0 = df["volume"].iloc[0]
        ax_v.plot(n, df["volume"] / v0 if v0 else df["volume"], color=color, label=name)
        bad = first_violation(df)
        if bad is not None:
            for ax in axes.ravel():
                ax.axvline(bad, color=color, ls=":", lw=1.2)
            ax_b.annotate(f"violation at n = {bad}", (bad, 0.0), xytext=(-4, 4),
                          textcoords="offset points", ha="right", fontsize=8, color=color)
    ax_b.axhline(0.0, color="0.5", lw=0.8)
    ax_b.axhline(1.0 / 3.0, color="0.8", lw=0.8)
    ax_b.set_ylabel("T barycentric coordinate")
    low = min(min(df["t_bary_min"].min() for df in frames.values()), 0.0)
    ax_b.set_ylim(max(low, -0.5) - 0.02, 0.36)
    smallest = min(df["diamond_area_min_rel"].min() for df in frames.values())
    if smallest < 1e-3:
        ax_a.axhline(COLLAPSE_AREA, color="0.5", lw=0.8)
    else:
        ax_a.set_ylim(bottom=min(0.3 * smallest, 1e-2))
    ax_a.set_ylabel("min diamond area / mean")
    ax_g.axhline(0.0, color="0.5", lw=0.8)
    ax_g.set_ylabel("smallest angle [deg] (< 0: folded)")
    ax_v.set_ylabel("volume / volume at n = 0")
    for ax in axes.ravel():
        for m in marks:
            ax.axvline(m, color="0.85", lw=0.8, zorder=0)
        ax.grid(alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("time step n")
    ax_b.legend(fontsize=7, loc="lower left")
    if title:
        fig.suptitle(title)
    fig.tight_layout()
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
