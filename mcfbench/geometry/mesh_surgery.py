"""Topological surgery at a neck pinch: cut the neck of a closed triangle mesh and cap both
sides, once the neck has shrunk below the mesh's resolution.

Mean curvature flow pinches a thin neck in finite time (the dumbbell; Grayson 1989,
Angenent 1992); the flow past the pinch is that of the two parts, each closed
(Altschuler, Angenent and Giga 1995 for a rotationally symmetric neck; the numerical
surgery of Huisken and Sinestrari 2009 and of Kovacs 2022, arXiv 2210.14046, cut
the neck and glue in caps). A mesh cannot follow the neck below its own resolution:
the neck's triangles fold or degenerate (the dumbbell's runs end ``inverted`` or
``degenerated`` a few steps after the pinch). :func:`find_neck` sees the neck before
that, :func:`cut_neck` cuts it.

The neck
--------
The mean curvature vector ``H n = -Delta X`` (the cotangent Laplacian over the
lumped mass, libigl's ``cotmatrix`` and ``massmatrix``; ``H`` the sum of the principal
curvatures) points towards the axis at a neck, and the Gaussian curvature (the angle
defect) is negative there (a saddle): the neck's vertex is the one of largest
``|H|`` among the vertices of negative angle defect. Its *ring* is the vertices
joined to it by edges through vertices of ``|H|`` at least half its own. The neck's
*axis* is the line that the ring's normal lines meet (on a surface of revolution
every normal line meets the axis): its direction the right singular vector of the
ring's unit vectors ``H n / |H n|`` of smallest singular value (they are all
perpendicular to it), its point ``c`` the least-squares point nearest to all the
normal lines, ``sum (I - u u^T)(c - p) = 0``. The neck's *radius* ``r`` is the
median distance of the ring's vertices from the axis.

The criterion
-------------
A neck is *pinched* when ``r < NECK_RESOLUTION * h``, ``h`` the mesh's resolution
(the run's initial mean edge length): half an edge. On the dumbbell the neck's
radius falls as ``r^2 = 2 (T - t)`` (a shrinking cylinder, ``r r' = -1``); at
``r = h / 2`` the runs of cotan, BGN and DDFV chord carried are 3-5 time steps
before their first fold or degenerate triangle (levels 1-2, tau = 0.004 and 0.001:
cut at steps 27, 26, 27 against ends at 31, 29, 30; at level 2 cotan's 97 against
102, BGN's 95 against 98).

The cut
-------
The plane through the neck's vertex perpendicular to the axis cuts the neck: the
*band* is the strip of triangles that the plane crosses (some vertex on each side)
joined by edges to a triangle of the neck's vertex (a tube's one ring of
triangles), and every triangle of a vertex within :data:`TUBE` neck radii of the
axis joined to the neck's vertex within that tube: the whole thin part. A flowed
neck's triangles are long along its axis and its vertices zigzag in radius (the
dumbbell's at level 1: rings at 0.02 and 0.037 from the axis within 0.05 of the
plane, the next at 0.07 and 0.17), so that the strip's own loops would mix both
rings; and at level 2 the neck is a tube of radius 0.025-0.03 over 0.1 of its
length, whose stumps, cut at one plane only, pinch again at once. The band is
removed, which leaves two boundary loops (one on each side), and each loop is
closed by a dome of rings, a hemisphere over the loop towards the plane
(:func:`_dome`), oriented as the triangles it meets. :func:`cut_neck` refuses
(``None`` and the reason) a cut that does not leave exactly two loops or does not
add one closed, consistently oriented component.

Area and volume removed
-----------------------
The band lies within ``r_band`` of the axis and within ``z_band`` of the plane
(the largest distance of its vertices from the axis and from the plane; ``z_band``
the thin part's length plus an edge), and its area stays below that of a tube of
radius ``r_band`` and height ``2 z_band``, ``4 pi r_band z_band`` (tested on the
dumbbell; a bound for a band that winds about the axis once without folding, not
for every surface); each cap, a hemisphere of radius at most ``r_band``, adds at
most ``2 pi r_band^2``. The reported ``area_removed`` is the area before minus
after, the ``volume_removed`` likewise.
"""

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from mcfbench.geometry import metrics
from mcfbench.geometry.collapse import (component_topology, component_volumes,
                                        mean_curvature_vectors)
from mcfbench.geometry.measures import vertex_components

NECK_RESOLUTION = 0.5
"""A neck whose radius is below this many times the mesh's resolution ``h`` is
pinched (module docstring)."""

TUBE = 2.0
"""The band also takes every triangle of a vertex within this many neck radii of the
axis (joined to the neck's vertex within that tube)."""

MIN_RING = 6
"""The fewest vertices of a neck's ring; and they surround the axis (no angle about
it without one of them wider than pi)."""

RING_FRACTION = 0.5
"""The neck's ring: vertices of ``|H|`` at least this fraction of the neck vertex's."""


class Neck(NamedTuple):
    """A neck found by :func:`find_neck`.

    Attributes
    ----------
    vertex : int
        The neck's vertex (largest ``|H|`` of negative angle defect).
    ring : (k,) int array
        The ring's vertices.
    centre : (3,) float array
        The axis's point nearest to the ring's normal lines.
    axis : (3,) float array
        Unit direction of the axis.
    radius : float
        Median distance of the ring's vertices from the axis.
    curvature : float
        ``|H|`` at the neck's vertex.
    """

    vertex: int
    ring: np.ndarray
    centre: np.ndarray
    axis: np.ndarray
    radius: float
    curvature: float


class Surgery(NamedTuple):
    """What :func:`cut_neck` did.

    Attributes
    ----------
    vertices : (n', 3) float array
        The kept vertices (in their order) and then one new vertex per cap.
    faces : (m', 3) int array
        The kept triangles (in their order, renumbered) and then the caps' triangles.
    keep_vertices : (n,) bool array
        The input's vertices kept (those of the band's triangles alone are dropped).
    keep_faces : (m,) bool array
        The input's triangles kept (all but the band's).
    where : (3,) float array
        The neck's point on the axis (in the cutting plane).
    radius : float
        The neck's radius (:class:`Neck`).
    band_radius, band_height : float
        ``r_band`` and ``z_band`` (module docstring).
    components_before, components_after : int
    area_removed, volume_removed : float
        Before minus after.
    band_area : float
        The removed triangles' area.
    """

    vertices: np.ndarray
    faces: np.ndarray
    keep_vertices: np.ndarray
    keep_faces: np.ndarray
    where: np.ndarray
    radius: float
    band_radius: float
    band_height: float
    components_before: int
    components_after: int
    area_removed: float
    volume_removed: float
    band_area: float


def angle_defects(vertices, faces):
    """``2 pi`` minus the angle sum at every vertex (the Gaussian curvature times its
    area; negative at a saddle), (n,) float array."""
    F = np.asarray(faces, dtype=np.int64)
    angles = np.radians(metrics.triangle_angles(vertices, F))
    return 2 * np.pi - np.bincount(F.ravel(), angles.ravel(), minlength=len(vertices))


class Curvature(NamedTuple):
    """The curvature of one mesh state that the neck (:func:`find_neck`) and the
    sharpness (:func:`mcfbench.geometry.reextraction.sharpness`) read
    (:func:`curvature`).

    Attributes
    ----------
    vectors : (n, 3) float array
        ``H n`` (:func:`mean_curvature_vectors`).
    defects : (n,) float array
        The angle defects (:func:`angle_defects`).
    """

    vectors: np.ndarray
    defects: np.ndarray


def curvature(vertices, faces):
    """The :class:`Curvature` of the mesh ``(vertices, faces)``: its one cotangent
    Laplacian and Voronoi mass."""
    return Curvature(mean_curvature_vectors(vertices, faces), angle_defects(vertices, faces))


def _adjacency(n, pairs):
    """The symmetric (n, n) adjacency of the index ``pairs`` (k, 2)."""
    i, j = pairs[:, 0], pairs[:, 1]
    return sp.coo_matrix((np.ones(2 * len(i)), (np.r_[i, j], np.r_[j, i])), shape=(n, n)).tocsr()


def _edges(F):
    return F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2)


def find_neck(vertices, faces, known=None):
    """The neck of a closed mesh (module docstring), or None when no vertex has a
    negative angle defect (and a finite, nonzero ``|H|``) or the neck vertex's ring is
    no ring (fewer than :data:`MIN_RING` vertices, or not around the axis: a dimple, a
    fold).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    known : Curvature, optional
        The mesh's :func:`curvature` when computed already (default: computed here).

    Returns
    -------
    Neck or None
    """
    V, F = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    Hn, defects = curvature(V, F) if known is None else known
    H = np.linalg.norm(Hn, axis=1)
    H = np.where(np.isfinite(H), H, 0.0)    # a vertex of no area (a raw mesh's) is no neck
    saddle = (defects < 0) & (H > 0)
    if not saddle.any():
        return None
    v0 = int(np.flatnonzero(saddle)[np.argmax(H[saddle])])
    strong = H >= RING_FRACTION * H[v0]
    E = _edges(F)
    E = E[strong[E].all(axis=1)]
    labels = connected_components(_adjacency(len(V), E), directed=False)[1]
    ring = np.flatnonzero(strong & (labels == labels[v0]))
    u = Hn[ring] / H[ring, None]
    axis = np.linalg.svd(u, full_matrices=False)[2][-1]
    P = np.eye(3)[None] - u[:, :, None] * u[:, None, :]          # (k, 3, 3)
    centre = np.linalg.lstsq(P.sum(0), np.einsum("kij,kj->i", P, V[ring]), rcond=None)[0]
    rho = _axis_distance(V[ring], centre, axis)
    d = V[ring] - centre
    e1 = np.cross(axis, np.eye(3)[np.argmin(np.abs(axis))])
    angle = np.sort(np.arctan2(d @ np.cross(axis, e1), d @ e1))
    if len(ring) < MIN_RING or np.diff(np.r_[angle, angle[0] + 2 * np.pi]).max() > np.pi:
        return None
    return Neck(v0, ring, centre, axis, float(np.median(rho)), float(H[v0]))


def _axis_distance(points, centre, axis):
    d = points - centre
    return np.linalg.norm(d - np.outer(d @ axis, axis), axis=1)


def pinched(neck, h, resolution=NECK_RESOLUTION):
    """Whether ``neck`` (a :class:`Neck` or None) is below ``resolution * h``."""
    return neck is not None and neck.radius < resolution * h


def cut_neck(vertices, faces, neck):
    """Cut ``neck`` and cap both sides (module docstring).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
        A closed, consistently oriented mesh.
    neck : Neck

    Returns
    -------
    surgery : Surgery or None
    reason : str
        Why there is no surgery (empty when there is one).
    """
    V, F = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    n, m = len(V), len(F)
    p0 = V[neck.vertex]
    z = (V - p0) @ neck.axis
    where = neck.centre + ((p0 - neck.centre) @ neck.axis) * neck.axis
    zf = z[F]
    crossing = (zf.min(axis=1) < 0) & (zf.max(axis=1) >= 0)
    # the crossing triangles' strip joined by edges to a triangle of the neck's vertex
    E = _edges(F)
    owner = np.repeat(np.arange(m), 3)
    key = np.sort(E, axis=1) @ np.array([n, 1])
    order = np.argsort(key, kind="stable")
    pair = owner[order].reshape(-1, 2) if len(order) % 2 == 0 else None
    if pair is None or not np.array_equal(key[order][0::2], key[order][1::2]):
        return None, "the mesh is not closed (an edge not shared by two triangles)"
    strip = pair[crossing[pair].all(axis=1)]
    labels = connected_components(_adjacency(m, strip), directed=False)[1]
    start = np.flatnonzero(crossing & (F == neck.vertex).any(axis=1))
    if not len(start):
        return None, "the cutting plane crosses no triangle of the neck's vertex"
    thin = _axis_distance(V, neck.centre, neck.axis) < TUBE * neck.radius
    near = connected_components(_adjacency(n, E[thin[E].all(axis=1)]), directed=False)[1]
    inside = thin & (near == near[neck.vertex])
    band = (crossing & np.isin(labels, labels[start])) | inside[F].any(axis=1)
    keep_faces = ~band
    kept = F[keep_faces]
    keep_vertices = np.zeros(n, bool)
    keep_vertices[kept.ravel()] = True
    number = np.cumsum(keep_vertices) - 1
    kept = number[kept]
    # the boundary edges left (directed as in their triangle), their loops
    directed = _edges(kept)
    undirected = np.sort(directed, axis=1) @ np.array([n, 1])
    _, index, counts = np.unique(undirected, return_index=True, return_counts=True)
    boundary = directed[index[counts == 1]]
    k = int(keep_vertices.sum())
    nloops, loop_of = connected_components(_adjacency(k, boundary), directed=False)
    on_loop = np.unique(boundary)
    loops = np.unique(loop_of[on_loop])
    degree = np.bincount(boundary.ravel(), minlength=k)[on_loop]
    if len(loops) != 2 or (degree != 2).any():
        return None, (f"removing the band of {int(band.sum())} triangles left "
                      f"{len(loops)} boundary loop(s), not two simple ones")
    Vk, points, caps = V[keep_vertices], [], []
    for loop in range(2):
        cap_points, cap_faces = _dome(Vk, boundary[loop_of[boundary[:, 0]] == loops[loop]],
                                      neck, where, k + sum(len(p) for p in points))
        points.append(cap_points)
        caps.append(cap_faces)
    V2 = np.vstack([Vk, *points])
    F2 = np.vstack([kept, *caps])
    before, labels1 = vertex_components(F, n)
    after, lab2 = vertex_components(F2, len(V2))
    chi, closed = component_topology(F2, lab2, after)
    if after != before + 1 or not closed.all() or not _oriented(F2):
        return None, (f"the cut left {after} component(s) from {before} (closed: "
                      f"{closed.all()}, oriented: {_oriented(F2)})")
    area0, area1 = metrics.area(V, F), metrics.area(V2, F2)
    vol0 = component_volumes(V, F, labels1[F[:, 0]], before).sum()
    vol1 = component_volumes(V2, F2, lab2[F2[:, 0]], after).sum()
    bv = np.unique(F[band])
    return Surgery(V2, F2, keep_vertices, keep_faces, where, neck.radius,
                   float(_axis_distance(V[bv], neck.centre, neck.axis).max()),
                   float(np.abs(z[bv]).max()), int(before), int(after), float(area0 - area1),
                   float(vol0 - vol1), float(metrics.area(V, F[band]))), ""


def _dome(V, edges, neck, where, first):
    """The cap of one loop: a dome of rings over it, towards the cutting plane.

    The loop's points ordered by their angle about the axis (seen from the plane),
    its centre ``c`` the polygon's centroid (its edges' midpoints weighted by their
    lengths), ``rho`` their mean distance from ``c`` across the axis, ``l`` the mean
    edge: rings at ``psi_j = (pi / 2) j / J``, ``J = round((pi / 2) rho / l)``, of
    radius ``rho cos psi_j`` and ``round(k cos psi_j)`` points (``k`` the loop's),
    ``rho' sin psi_j`` towards the plane (``rho' = min(rho, 0.9`` the centre's
    distance from the plane``)``), the last one a pole: a hemisphere meets the tube
    tangentially and its triangles keep about the loop's edge, where a flat fan of
    long thin triangles makes a rim the flow pulls into the axis within a few steps
    (the dumbbell's level 2). Neighbouring rings are joined by :func:`_zip`.

    Parameters
    ----------
    V : (n, 3) float array
    edges : (b, 2) int array
        The loop's boundary edges, as directed in their triangles.
    neck : Neck
    where : (3,) float array
        A point of the cutting plane.
    first : int
        The number of the cap's first new point.

    Returns
    -------
    points : (p, 3) float array
    faces : (q, 3) int array
        Oriented as the triangles the loop's edges belong to, when the loop is ordered
        by angle as along its edges (else the caller's orientation check refuses it).
    """
    ends = V[edges]
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    c = (length[:, None] * ends.mean(axis=1)).sum(axis=0) / length.sum()
    height = (c - where) @ neck.axis
    out = -np.sign(height) * neck.axis if height != 0 else neck.axis
    e1 = np.cross(out, np.eye(3)[np.argmin(np.abs(out))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(out, e1)
    ids = np.unique(edges)
    d = V[ids] - c
    theta = np.arctan2(d @ e2, d @ e1)
    order = np.argsort(theta)
    ring, angles = ids[order], theta[order]
    rho = float(np.linalg.norm(d - np.outer(d @ out, out), axis=1).mean())
    J = max(1, int(round(np.pi / 2 * rho / length.mean())))
    rise = min(rho, 0.9 * abs(height))
    points, faces, number = [], [], first
    for j in range(1, J + 1):
        psi = np.pi / 2 * j / J
        count = 1 if j == J else max(3, int(round(len(ids) * np.cos(psi))))
        a = angles[0] + 2 * np.pi * (np.arange(count) + 0.5) / count
        new = (c + rho * np.cos(psi) * (np.outer(np.cos(a), e1) + np.outer(np.sin(a), e2))
               + rise * np.sin(psi) * out)
        inner = number + np.arange(count)
        faces.append(_zip(ring, angles, inner, a))
        points.append(new)
        ring, angles, number = inner, a, number + count
    return np.vstack(points), np.vstack(faces)


def _zip(A, ta, B, tb):
    """The triangles joining ring ``A`` to the ring ``B`` inside it, both ordered by
    their angles ``ta``, ``tb`` (ascending, ``tb`` within ``[ta[0], ta[0] + 2 pi)``),
    walking both by angle: at each next angle of ``A`` the triangle ``(A_i, A_{i+1},
    B_current)``, of ``B`` the triangle ``(A_current, B_j, B_{j-1})``; a ring ``B`` of
    one point is a fan. Normals along ``e1 x e2`` of the angles' frame.

    Returns
    -------
    (len(A) + len(B) or len(A), 3) int array
    """
    ka, kb = len(A), len(B)
    step_b = tb if kb > 1 else np.empty(0)
    events = np.r_[ta[1:], ta[0] + 2 * np.pi, step_b]
    is_a = np.r_[np.ones(ka, bool), np.zeros(len(step_b), bool)][np.argsort(events,
                                                                        kind="stable")]
    a = np.cumsum(is_a) - is_a                       # A's steps before each event
    b = np.cumsum(~is_a) - ~is_a                     # B's steps before each event
    return np.where(is_a[:, None],
                    np.column_stack([A[a % ka], A[(a + 1) % ka], B[(b - 1) % kb]]),
                    np.column_stack([A[a % ka], B[b % kb], B[(b - 1) % kb]]))


def _oriented(F):
    """Every directed edge once (a closed, consistently oriented, edge-manifold mesh)."""
    directed = _edges(np.asarray(F, dtype=np.int64))
    n = int(directed.max()) + 1
    key = directed @ np.array([n, 1])
    reverse = directed[:, ::-1] @ np.array([n, 1])
    return len(np.unique(key)) == len(key) and np.isin(reverse, key).all()
