"""Mesh topology: the diamond mesh of a triangulated surface (Section 2.2.2).

One diamond cell per mesh edge: its two F-vertices ``a, b`` (the edge) and
the T-vertices of the two adjacent triangles ``t1, t2``. The triangle ``t1``
traverses the edge as ``a -> b``, ``t2`` as ``b -> a``. A boundary edge has
``t2 = -1`` (a boundary diamond cell is the triangle ``F_a, F_b, T_t1``).
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components


@dataclass(frozen=True)
class DiamondMesh:
    """Combinatorics of the diamond mesh.

    Attributes
    ----------
    n_f : int
        Number of F-vertices (mesh vertices).
    faces : (n_t, 3) numpy int array
        Triangles, consistently oriented.
    diamonds : (n_d, 4) numpy int array
        Rows ``(a, b, t1, t2)``: edge ``a -> b`` as traversed by triangle
        ``t1``; ``t2`` is the opposite triangle or ``-1`` on the boundary.
    halfedges : (n_t, 3) numpy int array
        Diamond of the half-edge ``faces[t, k] -> faces[t, (k + 1) % 3]``.
    """

    n_f: int
    faces: np.ndarray
    diamonds: np.ndarray
    halfedges: np.ndarray

    @property
    def n_t(self):
        """Number of T-vertices (triangles)."""
        return len(self.faces)

    @property
    def n_unknowns(self):
        """``n_V = n_F + n_T`` vertices of the diamond mesh."""
        return self.n_f + self.n_t

    @cached_property
    def boundary(self):
        """(n_d,) bool array: the diamond is a boundary diamond cell."""
        return self.diamonds[:, 3] < 0

    @cached_property
    def has_boundary(self):
        return bool(self.boundary.any())

    @cached_property
    def boundary_vertices(self):
        """(n_f,) bool array: the F-vertex lies on the boundary."""
        mask = np.zeros(self.n_f, dtype=bool)
        mask[self.diamonds[self.boundary, :2].ravel()] = True
        return mask


    @cached_property
    def adjacency(self):
        """(n_f, n_f) CSR matrix: the one-ring of F-vertex i is row i."""
        a, b = self.diamonds[:, 0], self.diamonds[:, 1]
        ones = np.ones(2 * len(a))
        adj = sp.csr_matrix((ones, (np.r_[a, b], np.r_[b, a])),
                            shape=(self.n_f, self.n_f))
        adj.sort_indices()
        return adj

    def one_ring(self, i):
        """Indices of the F-vertices adjacent to F-vertex ``i`` (sorted)."""
        adj = self.adjacency
        return adj.indices[adj.indptr[i]:adj.indptr[i + 1]]


def diamond_mesh(faces, n_vertices=None):
    """Build and validate the diamond mesh of a triangle list.

    Parameters
    ----------
    faces : (n_t, 3) array_like of int
        Triangles as vertex indices.
    n_vertices : int, optional
        Number of mesh vertices; defaults to ``faces.max() + 1``.

    Returns
    -------
    DiamondMesh

    Raises
    ------
    ValueError
        Fewer than 4 triangles, indices out of range, a triangle repeating
        a vertex, an unreferenced vertex, an edge shared by more than two
        triangles or a vertex joining separate fans of triangles
        (non-manifold), or two triangles that traverse their common edge in
        the same direction (inconsistent orientation). The message names
        the offending elements.
    """
    faces = np.asarray(faces)
    if faces.ndim != 2 or faces.shape[1] != 3:
        raise ValueError(f"faces must have shape (n_t, 3), got {faces.shape}")
    if not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"faces must be integers, got dtype {faces.dtype}")
    faces = faces.astype(np.int64)
    if len(faces) < 4:
        raise ValueError(
            f"a surface needs at least 4 triangles, got {len(faces)}")
    n_f = int(faces.max()) + 1 if n_vertices is None else int(n_vertices)
    if faces.min() < 0 or faces.max() >= n_f:
        raise ValueError(f"face indices must lie in [0, {n_f}), got "
                         f"[{faces.min()}, {faces.max()}]")
    repeated = np.flatnonzero((faces[:, 0] == faces[:, 1])
                              | (faces[:, 1] == faces[:, 2])
                              | (faces[:, 2] == faces[:, 0]))
    if len(repeated):
        raise ValueError("degenerate triangle(s) repeating a vertex: "
                         f"{_few(repeated)}")
    unreferenced = np.flatnonzero(np.bincount(faces.ravel(), minlength=n_f) == 0)
    if len(unreferenced):
        raise ValueError(f"unreferenced vertex(es): {_few(unreferenced)}")

    # Half-edges i -> j of every triangle, grouped by undirected edge.
    src = faces.ravel()
    dst = faces[:, [1, 2, 0]].ravel()
    tri = np.repeat(np.arange(len(faces)), 3)
    key = np.minimum(src, dst) * n_f + np.maximum(src, dst)
    order = np.argsort(key, kind="stable")
    key, src, dst, tri = key[order], src[order], dst[order], tri[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, len(key)])

    bad = starts[counts > 2]
    if len(bad):
        edges = [(int(src[s]), int(dst[s])) for s in bad[:5]]
        raise ValueError(f"non-manifold mesh: {len(bad)} edge(s) shared by "
                         f"more than two triangles, e.g. {edges}")
    inner = starts[counts == 2]
    same_dir = inner[src[inner] == src[inner + 1]]
    if len(same_dir):
        pairs = [(int(tri[s]), int(tri[s + 1])) for s in same_dir[:5]]
        raise ValueError("inconsistent orientation: triangle pairs "
                         f"{pairs} traverse their common edge in the same "
                         "direction")

    _check_vertex_fans(faces, n_f, tri[inner], tri[inner + 1], src[inner], dst[inner])

    t2 = np.full(len(starts), -1, dtype=np.int64)
    t2[counts == 2] = tri[inner + 1]
    # column-major: each column is contiguous for fast gathers
    diamonds = np.asfortranarray(np.column_stack([src[starts], dst[starts], tri[starts], t2]))
    halfedges = np.empty(len(key), dtype=np.int64)
    halfedges[order] = np.repeat(np.arange(len(starts)), counts)
    return DiamondMesh(n_f=n_f, faces=faces, diamonds=diamonds,
                       halfedges=halfedges.reshape(-1, 3))


def _check_vertex_fans(faces, n_f, t1, t2, a, b):
    """Refuse vertices whose triangles form more than one fan.

    Corners ``(t, vertex)`` are joined across every inner edge ``(a, b)``
    of triangles ``t1, t2`` at both of its vertices; a manifold vertex has
    all its corners in one connected component.
    """
    n_t = len(faces)
    corner = np.arange(3 * n_t).reshape(n_t, 3)

    def corner_of(t, v):
        return corner[t, np.argmax(faces[t] == v[:, None], axis=1)]

    rows = np.r_[corner_of(t1, a), corner_of(t1, b)]
    cols = np.r_[corner_of(t2, a), corner_of(t2, b)]
    graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(3 * n_t, 3 * n_t))
    _, label = connected_components(graph, directed=False)
    fans = np.unique(np.column_stack([faces.ravel(), label]), axis=0)[:, 0]
    bad = np.flatnonzero(np.bincount(fans, minlength=n_f) > 1)
    if len(bad):
        raise ValueError(f"non-manifold mesh: vertex(es) {_few(bad)} join separate "
                         "fans of triangles")


def _few(indices, limit=10):
    """Format the first few indices of an error report."""
    shown = ", ".join(str(int(i)) for i in indices[:limit])
    more = f" (and {len(indices) - limit} more)" if len(indices) > limit else ""
    return f"[{shown}]{more}"
