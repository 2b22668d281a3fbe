"""The harness's gate for input surfaces: validation and a one-line summary.

Every surface goes through :func:`validate_mesh` before any scheme
(``ddfv``, ``baselines``) sees it; the schemes do not check their input
again. :func:`summarize` describes a valid surface in one line.

What counts as a valid surface
------------------------------
An oriented 2-manifold triangle mesh, possibly with boundary, possibly in
several connected components:

* ``vertices`` is ``(n, 3)`` real, ``faces`` is ``(m, 3)`` integer with
  every index in ``[0, n)``; ``m >= 1``.
* No triangle repeats a vertex; no two triangles use the same three
  vertices (in any order); every vertex is used by a triangle
  (:func:`mcfbench.geometry.mesh_files.read_mesh` drops unused ones before).
* Every edge has one (boundary) or two (inner) triangles, and two
  triangles traverse their common edge in opposite directions (consistent
  orientation). The triangles around a vertex form one fan (no two
  surfaces touching at a point).
* Coordinates are finite, the bounding box diagonal is a finite double
  and the largest extent is at least the smallest normal double.
* No triangle has (numerically) zero area: ``area > 1e-12 * l**2`` with
  ``l`` the triangle's longest edge. The test is computed in a frame
  scaled per triangle, so it is the same at any scale (coordinates of
  1e200 or 1e-200 are fine as long as the shape is).

Choices
-------
* A single triangle is a valid (open) surface: its three vertices are on
  the boundary, so under Dirichlet boundary conditions nothing moves.
* Disconnected components are valid; each one flows on its own.
  :class:`MeshSummary` reports their number and the genus of each.
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

#: a triangle is degenerate when area <= ZERO_AREA * (longest edge)**2
ZERO_AREA = 1e-12

_TINY = np.finfo(float).tiny


class MeshError(ValueError):
    """An input surface is not valid.

    Attributes
    ----------
    kind : str
        Short name of the problem, e.g. ``"non-manifold edge"``; the
        message (``str(err)``) is a sentence naming the elements.
    """

    def __init__(self, kind, message):
        super().__init__(message)
        self.kind = kind


def validate_mesh(vertices, faces, *, vertex_ids=None, face_ids=None):
    """Check an input surface and return it as float64 / int64 arrays.

    Parameters
    ----------
    vertices : (n, 3) array_like of real numbers
    faces : (m, 3) array_like of int
        Triangles as indices into ``vertices``.
    vertex_ids, face_ids : (n,) and (m,) array_like of int, optional
        Numbers by which messages name vertices and triangles (e.g. their
        numbers in the file, see :func:`mcfbench.geometry.mesh_files.read_mesh`);
        default: their indices in ``vertices`` and ``faces``.

    Returns
    -------
    V : (n, 3) float64 array
    F : (m, 3) int64 array

    Raises
    ------
    MeshError (a ValueError)
        The first problem found, in this order: shapes and dtypes, indices
        out of range, NaN/inf coordinates, a triangle repeating a vertex,
        unreferenced vertices, duplicate triangles, non-manifold edges,
        inconsistent orientation, non-manifold vertices, coordinates that
        overflow or underflow, zero-area triangles. The message names the
        first few offending elements (see the module docstring).

    Examples
    --------
    >>> V = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    >>> validate_mesh(V, [[0, 1, 2]])[1].tolist()
    [[0, 1, 2]]
    >>> validate_mesh(V, [[0, 1, 1]])
    Traceback (most recent call last):
    ...
    mcfbench.geometry.mesh.MeshError: triangle(s) [0] repeat a vertex, e.g. triangle 0 = (0, 1, 1)
    """
    V, F = _arrays(vertices, faces)
    n, m = len(V), len(F)
    vid = np.arange(n) if vertex_ids is None else np.asarray(vertex_ids)
    fid = np.arange(m) if face_ids is None else np.asarray(face_ids)

    def tri(t):
        return f"triangle {int(fid[t])} = ({', '.join(str(int(vid[v])) for v in F[t])})"

    out = np.flatnonzero(((F < 0) | (F >= n)).any(axis=1))
    if len(out):
        bad = F[out][(F[out] < 0) | (F[out] >= n)]
        raise MeshError("index out of range",
                        f"face indices out of range: triangle(s) {first_ids(fid[out])} refer to "
                        f"vertex index(es) {first_ids(np.unique(bad))}, but there are {n} "
                        f"vertices (valid indices 0 to {n - 1})")
    F = F.astype(np.int64)

    nonfinite = np.flatnonzero(~np.isfinite(V).all(axis=1))
    if len(nonfinite):
        raise MeshError("non-finite coordinate",
                        f"NaN or inf coordinates at vertex(es) {first_ids(vid[nonfinite])}")

    repeated = np.flatnonzero((F[:, 0] == F[:, 1]) | (F[:, 1] == F[:, 2])
                              | (F[:, 2] == F[:, 0]))
    if len(repeated):
        raise MeshError("repeated vertex",
                        f"triangle(s) {first_ids(fid[repeated])} repeat a vertex, e.g. "
                        f"{tri(repeated[0])}")

    unused = np.flatnonzero(np.bincount(F.ravel(), minlength=n) == 0)
    if len(unused):
        raise MeshError("unreferenced vertex",
                        f"unreferenced vertex(es) {first_ids(vid[unused])}: no triangle uses "
                        "them (remove them first; read_mesh drops them)")

    S = np.sort(F, axis=1)
    order = np.lexsort((S[:, 2], S[:, 1], S[:, 0]))     # stable: equal rows by index
    S = S[order]
    again = np.r_[False, (S[1:] == S[:-1]).all(axis=1)]
    if again.any():
        first = order[np.maximum.accumulate(np.where(again, 0, np.arange(m)))]
        later = np.flatnonzero(again)
        pairs = ", ".join(f"({int(fid[first[i]])}, {int(fid[order[i]])})" for i in later[:5])
        raise MeshError("duplicate triangle",
                        f"duplicate triangles (the same three vertices): {len(later)} "
                        f"triangle(s) repeat an earlier one, pairs {pairs}")

    edges = _edges(F, n)
    bad = np.flatnonzero(edges.count > 2)
    if len(bad):
        shown = "; ".join(
            f"edge ({int(vid[edges.a[s]])}, {int(vid[edges.b[s]])}) is shared by "
            f"triangles {first_ids(fid[edges.tri[s:s + c]])}"
            for s, c in zip(edges.start[bad[:3]], edges.count[bad[:3]]))
        raise MeshError("non-manifold edge",
                        f"non-manifold edge(s): {len(bad)} edge(s) have more than two "
                        f"triangles: {shown}")

    inner = edges.start[edges.count == 2]
    t1, t2 = edges.tri[inner], edges.tri[inner + 1]
    same = np.flatnonzero(edges.src[inner] == edges.src[inner + 1])
    if len(same):
        shown = "; ".join(
            f"triangles {int(fid[t1[i]])} and {int(fid[t2[i]])} both traverse edge "
            f"{int(vid[edges.src[inner[i]]])} -> {int(vid[edges.dst[inner[i]]])}"
            for i in same[:3])
        raise MeshError("inconsistent orientation",
                        f"inconsistent orientation at {len(same)} edge(s): {shown}")

    fans = _fan_count(F, n, edges.he[inner], edges.he[inner + 1])
    bad = np.flatnonzero(fans > 1)
    if len(bad):
        raise MeshError("non-manifold vertex",
                        f"non-manifold vertex(es) {first_ids(vid[bad])}: the triangles around "
                        "each form more than one fan, as where two surfaces touch at a "
                        f"point (vertex {int(vid[bad[0]])} has {int(fans[bad[0]])} fans)")

    _check_range(V)
    geo = _triangle_geometry(V, F, angles=False)
    zero = np.flatnonzero(~(geo.area_rel > ZERO_AREA))
    if len(zero):
        raise MeshError("zero-area triangle",
                        f"zero-area (degenerate) triangle(s) {first_ids(fid[zero])}: area <= "
                        f"{ZERO_AREA:g} x (longest edge)^2, e.g. {tri(zero[0])}")
    return V, F


@dataclass(frozen=True)
class MeshSummary:
    """Size, topology and quality of a valid surface (see :func:`summarize`).

    Attributes
    ----------
    vertices, faces, edges : int
    components : int
        Connected components.
    euler_characteristic : int
        ``vertices - edges + faces`` (sum over the components).
    genus : tuple of int
        Per component, ``g = (2 - chi - b) / 2`` with ``chi`` its Euler
        characteristic and ``b`` its boundary loops: for a closed component
        its genus, for an open one the genus of the closed surface obtained
        by capping each boundary loop with a disc (a disc or a cylinder has
        genus 0).
    boundary_loops : int
        Closed chains of boundary edges (0 for a closed surface).
    smallest_angle : float
        Smallest angle of all triangles, in degrees.
    area_ratio : float
        Largest over smallest triangle area.
    mean_edge : float
        Mean edge length (each edge once).
    """

    vertices: int
    faces: int
    edges: int
    components: int
    euler_characteristic: int
    genus: tuple
    boundary_loops: int
    smallest_angle: float
    area_ratio: float
    mean_edge: float

    @property
    def closed(self):
        return self.boundary_loops == 0

    def __str__(self):
        genus = str(self.genus[0]) if len(self.genus) == 1 else f"[{', '.join(map(str, self.genus))}]"
        edge = (f"{self.mean_edge:.4f}" if 1e-3 <= self.mean_edge < 1e4
                else f"{self.mean_edge:.3e}")
        return (f"{count_phrase(self.vertices, 'vertex', 'vertices')}, "
                f"{count_phrase(self.faces, 'face')}, {count_phrase(self.components, 'component')}, "
                f"genus {genus}, {count_phrase(self.boundary_loops, 'boundary loop')}, "
                f"smallest angle {self.smallest_angle:.1f} deg, "
                f"area ratio {self.area_ratio:.2f}, mean edge {edge}")


def summarize(vertices, faces):
    """Describe a surface: counts, topology and triangle quality.

    The surface is validated first (:func:`validate_mesh`), so this raises
    the same :class:`MeshError` for invalid input.

    Returns
    -------
    MeshSummary
        ``str(summary)`` is one line, e.g. ``"12 vertices, 20 faces,
        1 component, genus 0, 0 boundary loops, smallest angle 60.0 deg,
        area ratio 1.00, mean edge 1.0515"``.
    """
    V, F = validate_mesh(vertices, faces)
    n, m = len(V), len(F)
    edges = _edges(F, n)
    a, b = edges.a[edges.start], edges.b[edges.start]
    n_e = len(a)

    graph = sp.coo_matrix((np.ones(n_e), (a, b)), shape=(n, n))
    n_comp, label = connected_components(graph, directed=False)

    rim = edges.count == 1
    ra, rb = a[rim], b[rim]
    rim_graph = sp.coo_matrix((np.ones(len(ra)), (ra, rb)), shape=(n, n))
    _, rim_label = connected_components(rim_graph, directed=False)
    # in a valid surface every boundary vertex has exactly two boundary
    # edges, so each component of the boundary graph is one loop
    loop_vertex = np.unique(rim_label[ra], return_index=True)[1]
    loops = np.bincount(label[ra[loop_vertex]], minlength=n_comp)

    chi = (np.bincount(label, minlength=n_comp) - np.bincount(label[a], minlength=n_comp)
           + np.bincount(label[F[:, 0]], minlength=n_comp))
    genus = tuple(int(g) for g in (2 - chi - loops) // 2)

    geo = _triangle_geometry(V, F)
    with np.errstate(over="ignore"):
        ratio = float(np.exp(geo.log_area.max() - geo.log_area.min()))
    d = V[b] - V[a]
    scale = np.abs(d).max(axis=1)
    length = scale * np.linalg.norm(d / scale[:, None], axis=1)
    return MeshSummary(
        vertices=n, faces=m, edges=n_e, components=int(n_comp),
        euler_characteristic=int(chi.sum()), genus=genus,
        boundary_loops=int(loops.sum()),
        smallest_angle=float(np.degrees(geo.smallest_angle.min())),
        area_ratio=ratio, mean_edge=float(np.mean(length)))


# --- helpers -------------------------------------------------------------

def _arrays(vertices, faces):
    """Shapes and dtypes; returns float64 vertices and the raw face array."""
    try:
        V, F = np.asarray(vertices), np.asarray(faces)
    except ValueError as err:  # ragged nested lists
        raise MeshError("shape", f"vertices and faces must be rectangular arrays: {err}") from None
    if V.dtype.kind not in "iuf":
        raise MeshError("dtype", f"vertices must be real numbers, got dtype {V.dtype}")
    if V.ndim != 2 or V.shape[1] != 3:
        raise MeshError("shape", f"vertices must have shape (n, 3), got shape {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise MeshError("shape", f"faces must have shape (m, 3) (triangles), got shape "
                        f"{F.shape}")
    if F.dtype.kind not in "iu":
        raise MeshError("dtype", f"faces must be integer vertex indices, got dtype {F.dtype}")
    if len(F) == 0:
        raise MeshError("no triangles", "the surface has no triangles")
    return V.astype(np.float64), F


@dataclass
class _Edges:
    """Half-edges sorted by undirected edge.

    Half-edge ``h`` (``3 t + k``) goes from ``F[t, k]`` to ``F[t, (k + 1) % 3]``
    in triangle ``t``; after sorting, ``he[i]`` is its number, ``src[i] ->
    dst[i]`` its direction, ``tri[i]`` its triangle; ``a = min(src, dst)``,
    ``b = max(src, dst)``; ``start[e]``, ``count[e]``: the half-edges of
    edge ``e``.
    """
    he: np.ndarray
    src: np.ndarray
    dst: np.ndarray
    tri: np.ndarray
    a: np.ndarray
    b: np.ndarray
    start: np.ndarray
    count: np.ndarray


def _edges(F, n):
    src = F.ravel()
    dst = F[:, [1, 2, 0]].ravel()
    lo, hi = np.minimum(src, dst), np.maximum(src, dst)
    he = np.argsort(lo * np.int64(n) + hi, kind="stable")
    src, dst, a, b = src[he], dst[he], lo[he], hi[he]
    start = np.flatnonzero(np.r_[True, (a[1:] != a[:-1]) | (b[1:] != b[:-1])])
    count = np.diff(np.r_[start, len(a)])
    return _Edges(he, src, dst, he // 3, a, b, start, count)


def _fan_count(F, n, h1, h2):
    """Number of fans of triangles around each vertex (1 for a manifold vertex).

    Corners are numbered like the half-edges leaving them. Across an inner
    edge whose half-edges are ``h1: a -> b`` and ``h2: b -> a``, the corners
    at ``a`` (``h1`` and the successor of ``h2``) and at ``b`` (``h2`` and
    the successor of ``h1``) are joined; the fans of a vertex are the
    connected components of its corners.
    """
    def succ(h):
        return h - h % 3 + (h % 3 + 1) % 3

    rows, cols = np.r_[h1, h2], np.r_[succ(h2), succ(h1)]
    m3 = 3 * len(F)
    graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(m3, m3))
    n_label, label = connected_components(graph, directed=False)
    vertex_of = np.empty(n_label, dtype=np.int64)   # each fan lies at one vertex
    vertex_of[label] = F.ravel()
    return np.bincount(vertex_of, minlength=n)


def _check_range(V):
    """Refuse coordinates whose differences overflow or lose all precision."""
    with np.errstate(over="ignore", invalid="ignore"):
        extent = V.max(axis=0) - V.min(axis=0)
    if not np.isfinite(extent).all():
        axis = "xyz"[int(np.argmax(~np.isfinite(extent)))]
        raise MeshError("overflow",
                        f"coordinates overflow: the extent of the mesh along {axis} "
                        f"(max - min) is not a finite double (coordinates up to "
                        f"{np.abs(V).max():.3g})")
    largest = extent.max()
    with np.errstate(over="ignore"):
        diagonal = largest * np.linalg.norm(extent / largest) if largest > 0 else 0.0
    if not np.isfinite(diagonal):
        raise MeshError("overflow",
                        "coordinates overflow: the diagonal of the bounding box is not a "
                        f"finite double (extent {extent.tolist()})")
    if 0 < largest < _TINY:
        raise MeshError("underflow",
                        f"coordinates too small: the largest extent of the mesh, "
                        f"{largest:.3g}, is below the smallest normal double "
                        f"({_TINY:.3g}); rescale the mesh")


@dataclass
class _TriangleGeometry:
    area_rel: np.ndarray        # area / (longest edge)^2
    log_area: np.ndarray        # natural log of the area
    smallest_angle: np.ndarray  # radians


def _triangle_geometry(V, F, angles=True):
    """Scale-free triangle measures, each triangle in its own scaled frame.

    The edge vectors of a triangle are divided by their largest absolute
    component (exact up to rounding, no overflow or underflow), so areas
    and angles are computed on numbers of order one whatever the scale of
    the coordinates. Without ``angles``, only ``area_rel``.
    """
    p = (V - V.min(axis=0))[F]                      # shift: differences stay finite
    e = p[:, [1, 2, 0]] - p                         # e_k = p_{k+1} - p_k
    scale = np.abs(e).max(axis=(1, 2))
    safe = np.where(scale > 0, scale, 1.0)
    e /= safe[:, None, None]
    cross = np.cross(e[:, 0], e[:, 1])
    twice_area = np.sqrt(np.einsum("tc,tc->t", cross, cross))
    length2 = np.einsum("tkc,tkc->tk", e, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        area_rel = np.where(scale > 0, 0.5 * twice_area / length2.max(axis=1), 0.0)
        if not angles:
            return _TriangleGeometry(area_rel, None, None)
        log_area = np.log(0.5 * twice_area) + 2 * np.log(safe)
        # angle at corner k between e_k and -e_{k-1}
        dot = -np.einsum("tkc,tkc->tk", e, e[:, [2, 0, 1]])
        angle = np.arctan2(twice_area[:, None], dot)
    return _TriangleGeometry(area_rel, log_area, angle.min(axis=1))


def first_ids(ids, limit=10):
    """Format the first few numbers of an error report."""
    ids = np.asarray(ids).ravel()
    shown = ", ".join(str(int(i)) for i in ids[:limit])
    more = f" (and {len(ids) - limit} more)" if len(ids) > limit else ""
    return f"[{shown}]{more}"


def count_phrase(k, singular, plural=None):
    """``"1 vertex"``, ``"3 vertices"``: a count with its noun."""
    return f"{k} {singular if k == 1 else (plural or singular + 's')}"
