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
``min_angle``, ``primal_area_min_rel``, ``flipped``, ``worst_triangle``
    (``min_angle`` and ``flipped`` are named as in the monitor of every run,
    :func:`mcfbench.running.run.run`, and in the run records)
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
:func:`first_violation`; its plots are in :mod:`mcfbench.presentation.quality_plots`.
The covolume ratio (:func:`mcfbench.geometry.metrics.covolume_ratio`) of the scheme's own covolumes is
sampled with the smallest angle by the monitor of every run
(:func:`mcfbench.running.run.run`, the record's ``series``).
"""

import numpy as np
import pandas as pd

from ddfv.geometry import diamond_corners, diamond_geometry, t_barycentric
from ddfv.topology import diamond_mesh

#: relative diamond area below which a diamond cell counts as collapsed
COLLAPSE_AREA = 1e-8

COLUMNS = ("n", "t", "t_bary_min", "t_bary_median", "diamond_area_min_rel",
           "angle_min_deg", "area", "volume", "worst_t", "worst_diamond", "family",
           "min_angle", "primal_area_min_rel", "flipped", "worst_triangle")

#: the monitors of the diamond mesh (empty for ``vertex`` runs)
DIAMOND_COLUMNS = ("t_bary_min", "t_bary_median", "diamond_area_min_rel", "angle_min_deg",
                   "worst_t", "worst_diamond")
_INTEGER_COLUMNS = ("worst_t", "worst_diamond", "flipped", "worst_triangle")


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
        ``min_angle``, ``primal_area_min_rel``,
        ``flipped``, ``worst_triangle`` (see module docstring).

    Examples
    --------
    >>> from mcfbench.geometry.surfaces import icosphere
    >>> q = primal_quality(*icosphere(1))
    >>> round(q["min_angle"], 1), q["flipped"]
    (55.6, 0)
    """
    from mcfbench.geometry.metrics import flipped_triangles, min_angle, triangle_areas

    V = np.asarray(vertices, dtype=float)
    areas = triangle_areas(V, faces)
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = areas / areas.mean()
    finite = np.isfinite(V).all()
    return {
        "min_angle": min_angle(V, faces) if finite else float("nan"),
        "primal_area_min_rel": float(rel.min()) if finite else float("nan"),
        "flipped": flipped_triangles(V, faces) if finite else 0,
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

    A flow whose frame has extra points (DDFV's T-vertices,
    :meth:`mcfbench.running.flow.SchemeFlow.frame`) gets :func:`mesh_quality`,
    any other flow :func:`vertex_quality` of its frame's vertices and
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
        frame = flow.frame()      # the mesh vertices, and DDFV's T-vertices
        if "extra_points" in frame:
            if self._mesh is None:
                self._mesh = diamond_mesh(flow.faces, len(frame["vertices"]))
            row.update(mesh_quality(self._mesh, frame["vertices"], frame["extra_points"]))
        else:
            row.update(vertex_quality(frame["vertices"], flow.faces))
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
    collapse_area``) or folded over (``flipped > 0``). NaN monitors
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
    vertex = vertex_rows(df)
    diamond = ~(df["t_bary_min"] >= 0) | ~(df["diamond_area_min_rel"] >= collapse_area)
    if not vertex.any():
        return diamond
    primal = ~(df["primal_area_min_rel"] >= collapse_area) \
        | (df["flipped"].fillna(0).astype(float) > 0)
    return pd.Series(np.where(vertex, primal, diamond), index=df.index)


def describe_violation(df, collapse_area=COLLAPSE_AREA):
    """One sentence on the first violation, or ``""`` when there is none."""
    bad = violations(df, collapse_area)
    if not bad.any():
        return ""
    row = df.loc[bad].iloc[0]
    what = []
    if vertex_rows(df.loc[bad].iloc[:1]).iloc[0]:
        if not row["primal_area_min_rel"] >= collapse_area:
            what.append(f"triangle {_index(row['worst_triangle'])} collapsed "
                        f"(relative area {row['primal_area_min_rel']:.3g})")
        if row["flipped"] > 0:
            what.append(f"{int(row['flipped'])} triangle(s) folded over")
    else:
        if not row["t_bary_min"] >= 0:
            what.append(f"T-vertex {_index(row['worst_t'])} left its triangle "
                        f"(barycentric {row['t_bary_min']:.3g})")
        if not row["diamond_area_min_rel"] >= collapse_area:
            what.append(f"diamond {_index(row['worst_diamond'])} collapsed "
                        f"(relative area {row['diamond_area_min_rel']:.3g})")
    return f"step {int(row['n'])} (t = {row['t']:.6g}): " + " and ".join(what)


def vertex_rows(df):
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
