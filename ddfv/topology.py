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
from scipy.sparse.csgraph import reverse_cuthill_mckee


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

    def diamond_blocks(self, parts):
        """The diamonds grouped so that ``parts`` threads can scatter into per-vertex
        arrays (covolumes, matrix rows) without two of them writing one entry.

        F-vertex ``i`` belongs to part ``i * parts // n_f`` and T-vertex ``t``
        to part ``t * parts // n_t``; in the locality numbering
        (:func:`locality_order`) both are contiguous regions of the surface.
        Block ``k < parts`` holds the diamonds whose four vertices all lie in
        part ``k``; the last block the diamonds across parts (to be done
        after the others, on one thread). Each block keeps the diamonds in
        their order; with ``parts = 1`` the one block is every diamond in
        order.

        Parameters
        ----------
        parts : int

        Returns
        -------
        order : (n_d,) uint64 array
            The diamonds, block by block.
        starts : (parts + 2,) uint64 array
            Block ``k`` is ``order[starts[k]:starts[k + 1]]``.
        """
        cache = self.__dict__.setdefault("_blocks", {})
        if parts not in cache:
            a, b, t1, t2 = self.diamonds.T
            part_f = np.arange(self.n_f) * parts // self.n_f
            part_t = np.arange(self.n_t) * parts // max(self.n_t, 1)
            part = part_f[a]
            across = (part_f[b] != part) | (part_t[t1] != part)
            across |= (t2 >= 0) & (part_t[np.maximum(t2, 0)] != part)
            block = np.where(across, parts, part)
            order = np.argsort(block, kind="stable")
            starts = np.searchsorted(block[order], np.arange(parts + 2))
            cache[parts] = (order.astype(np.uint64), starts.astype(np.uint64))
        return cache[parts]

    def one_ring(self, i):
        """Indices of the F-vertices adjacent to F-vertex ``i`` (sorted)."""
        adj = self.adjacency
        return adj.indices[adj.indptr[i]:adj.indptr[i + 1]]


def diamond_mesh(faces, n_vertices=None):
    """Build the diamond mesh of a triangle list.

    The surface is not validated here: the harness checks every input
    surface (manifold, consistently oriented, no unreferenced vertices,
    no degenerate triangles, ...) before a scheme sees it. This function
    only refuses what it cannot build diamonds from.

    Parameters
    ----------
    faces : (n_t, 3) array_like of int
        Triangles as vertex indices, consistently oriented.
    n_vertices : int, optional
        Number of mesh vertices; defaults to ``faces.max() + 1``.

    Returns
    -------
    DiamondMesh

    Raises
    ------
    ValueError
        ``faces`` is not an (n_t, 3) integer array, an edge has more than
        two triangles, or two triangles traverse their common edge in the
        same direction.
    """
    faces = np.asarray(faces)
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ValueError("faces must be an (n_t, 3) integer array, got shape "
                         f"{faces.shape}, dtype {faces.dtype}")
    faces = faces.astype(np.int64)
    n_f = int(faces.max()) + 1 if n_vertices is None else int(n_vertices)
    base = max(n_f, int(faces.max()) + 1)  # keys stay distinct whatever the indices

    # Half-edges i -> j of every triangle, grouped by undirected edge.
    src = faces.ravel()
    dst = faces[:, [1, 2, 0]].ravel()
    tri = np.repeat(np.arange(len(faces)), 3)
    key = np.minimum(src, dst) * base + np.maximum(src, dst)
    order = np.argsort(key, kind="stable")
    key, src, dst, tri = key[order], src[order], dst[order], tri[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    counts = np.diff(np.r_[starts, len(key)])

    bad = starts[counts > 2]
    if len(bad):
        raise ValueError(f"cannot build diamonds: edge ({src[bad[0]]}, {dst[bad[0]]}) "
                         "has more than two triangles (non-manifold)")
    inner = starts[counts == 2]
    same_dir = inner[src[inner] == src[inner + 1]]
    if len(same_dir):
        s = same_dir[0]
        raise ValueError(f"cannot build diamonds: triangles {tri[s]} and {tri[s + 1]} "
                         f"both traverse edge {src[s]} -> {dst[s]} (inconsistent orientation)")

    t2 = np.full(len(starts), -1, dtype=np.int64)
    t2[counts == 2] = tri[inner + 1]
    # column-major: each column is contiguous for fast gathers
    diamonds = np.asfortranarray(np.column_stack([src[starts], dst[starts], tri[starts], t2]))
    halfedges = np.empty(len(key), dtype=np.int64)
    halfedges[order] = np.repeat(np.arange(len(starts)), counts)
    return DiamondMesh(n_f=n_f, faces=faces, diamonds=diamonds,
                       halfedges=halfedges.reshape(-1, 3))


def locality_order(faces, n_vertices):
    """A numbering of the vertices and triangles that keeps neighbours close in memory.

    Vertices in reverse Cuthill-McKee order of the edge graph; triangles
    sorted by the new numbers of their corners (smallest first). The
    diamonds built from the renumbered triangles are sorted by their
    smaller vertex (:func:`diamond_mesh`), so every loop over the
    diamonds, the CSR rows and the product with the system matrix reads
    its neighbours from nearby addresses: the band of the system matrix
    shrinks from the whole matrix to a few hundred rows. Not part of the
    scheme: the scheme is invariant under any renumbering
    (``tests/ddfv/test_flow.py``).

    Parameters
    ----------
    faces : (n_t, 3) int array
    n_vertices : int

    Returns
    -------
    vertex_order : (n_vertices,) int64 array
        ``vertex_order[j]``: the vertex numbered ``j`` in the new numbering.
    face_order : (n_t,) int64 array
        ``face_order[j]``: the triangle numbered ``j``.
    """
    faces = np.asarray(faces, dtype=np.int64)
    src, dst = faces.ravel(), faces[:, [1, 2, 0]].ravel()
    graph = sp.csr_matrix((np.ones(len(src), dtype=np.int8), (src, dst)),
                          shape=(n_vertices, n_vertices))
    vertex_order = reverse_cuthill_mckee((graph + graph.T).tocsr(), symmetric_mode=True)
    vertex_order = vertex_order.astype(np.int64)
    rank = np.empty(n_vertices, dtype=np.int64)
    rank[vertex_order] = np.arange(n_vertices)
    corners = np.sort(rank[faces], axis=1)
    face_order = np.lexsort((corners[:, 2], corners[:, 1], corners[:, 0]))
    return vertex_order, face_order
