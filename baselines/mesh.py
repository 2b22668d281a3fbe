"""Edge topology of a triangle mesh and the CSR pattern of its vertex Laplacian.

Shared by the vertex-based baselines (:mod:`baselines.cotan`,
:mod:`baselines.cmcf`, :mod:`baselines.bgn`). Everything is built once per
mesh with a few vectorised numpy operations (no loop over vertices, edges
or triangles); the input mesh is assumed validated by the harness
(manifold, consistently oriented, no degenerate triangles).

Conventions
-----------
Corner ``k`` of triangle ``t`` is ``faces[t, k]``; the edge *opposite*
corner ``k`` joins ``faces[t, k+1]`` and ``faces[t, k+2]`` (indices mod
3). This is libigl's convention for ``igl.cotmatrix_entries`` and the one of
the cotangent formula: the weight of an edge is the cotangent of the angle
at the corner opposite it.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class EdgeMesh:
    """Edges, edge-adjacency and boundary of a triangle mesh.

    Attributes
    ----------
    faces : (m, 3) int64 array
    n_vertices : int
    edges : (E, 2) int64 array
        Unique edges ``(a, b)``, ``a < b``, sorted.
    face_edges : (m, 3) int64 array
        ``face_edges[t, k]``: the edge opposite corner ``k`` of triangle ``t``.
    edge_faces : (E, 2) int64 array
        The triangles at each edge; ``edge_faces[e, 1] = -1`` on the boundary.
    face_neighbours : (m, 3) int64 array
        ``face_neighbours[t, k]``: the triangle across the edge opposite
        corner ``k``, ``-1`` on the boundary.
    boundary_vertices : (n,) bool array
        Vertices on an edge with one triangle (the Dirichlet vertices).
    """

    faces: np.ndarray
    n_vertices: int
    edges: np.ndarray
    face_edges: np.ndarray
    edge_faces: np.ndarray
    face_neighbours: np.ndarray
    boundary_vertices: np.ndarray

    @property
    def n_faces(self):
        return len(self.faces)

    @property
    def n_edges(self):
        return len(self.edges)

    @property
    def has_boundary(self):
        return bool(self.boundary_vertices.any())


def edge_mesh(faces, n_vertices):
    """The :class:`EdgeMesh` of ``faces``.

    Parameters
    ----------
    faces : (m, 3) int array
        Triangles of a manifold mesh (every edge in one or two triangles).
    n_vertices : int

    Returns
    -------
    EdgeMesh

    Examples
    --------
    >>> mesh = edge_mesh(np.array([[0, 1, 2], [0, 2, 3]]), 4)
    >>> mesh.edges.tolist()
    [[0, 1], [0, 2], [0, 3], [1, 2], [2, 3]]
    >>> mesh.face_neighbours.tolist(), mesh.boundary_vertices.tolist()
    ([[-1, 1, -1], [-1, -1, 0]], [True, True, True, True])
    """
    F = np.ascontiguousarray(faces, dtype=np.int64)
    if F.ndim != 2 or F.shape[1] != 3:
        raise ValueError(f"faces must have shape (m, 3), got {F.shape}")
    n, m = int(n_vertices), len(F)
    # half-edge opposite corner k: faces[t, k+1] -> faces[t, k+2]
    tail, head = F[:, [1, 2, 0]], F[:, [2, 0, 1]]
    lo, hi = np.minimum(tail, head).ravel(), np.maximum(tail, head).ravel()
    keys, inverse, counts = np.unique(lo * n + hi, return_inverse=True, return_counts=True)
    if counts.max(initial=0) > 2:
        raise ValueError("faces are not a manifold mesh: an edge lies in more than two "
                         "triangles")
    edges = np.stack([keys // n, keys % n], axis=1)
    face_edges = inverse.reshape(m, 3)
    # the (one or two) triangles of each edge, in order of appearance
    owner = np.repeat(np.arange(m, dtype=np.int64), 3)
    order = np.argsort(inverse, kind="stable")
    first = np.concatenate([[0], np.cumsum(counts)[:-1]])
    edge_faces = np.full((len(keys), 2), -1, dtype=np.int64)
    edge_faces[:, 0] = owner[order[first]]
    two = counts == 2
    edge_faces[two, 1] = owner[order[first[two] + 1]]
    across = edge_faces[face_edges]                                     # (m, 3, 2)
    mine = across[..., 0] == np.arange(m)[:, None]
    face_neighbours = np.where(mine, across[..., 1], across[..., 0])
    boundary = np.zeros(n, dtype=bool)
    boundary[edges[~two].ravel()] = True
    return EdgeMesh(F, n, edges, face_edges, edge_faces, face_neighbours, boundary)


@dataclass(frozen=True)
class LaplacianPattern:
    """CSR sparsity pattern of a vertex Laplacian: the edges and the diagonal.

    Attributes
    ----------
    indptr : (n + 1,) int32 array
    indices : (nnz,) int32 array
        Column indices, sorted within each row; ``nnz = n + 2 E``.
    rows : (nnz,) int64 array
        Row of each stored entry.
    edge_slots : (E, 2) int64 array
        Positions in ``data`` of the entries ``(a, b)`` and ``(b, a)`` of
        each edge.
    diag_slots : (n,) int64 array
        Position of ``(i, i)``.
    corner_slots : (m, 3, 2) int64 array
        ``edge_slots`` of the edge opposite each corner, what the assembly
        kernel scatters into.
    """

    indptr: np.ndarray
    indices: np.ndarray
    rows: np.ndarray
    edge_slots: np.ndarray
    diag_slots: np.ndarray
    corner_slots: np.ndarray

    @property
    def shape(self):
        n = len(self.indptr) - 1
        return (n, n)

    @property
    def nnz(self):
        return len(self.indices)


def laplacian_pattern(mesh):
    """The CSR pattern of the vertex Laplacian of ``mesh``.

    Parameters
    ----------
    mesh : EdgeMesh

    Returns
    -------
    LaplacianPattern

    Examples
    --------
    >>> p = laplacian_pattern(edge_mesh(np.array([[0, 1, 2]]), 3))
    >>> p.indptr.tolist(), p.indices.tolist()
    ([0, 3, 6, 9], [0, 1, 2, 0, 1, 2, 0, 1, 2])
    >>> p.edge_slots.tolist(), p.diag_slots.tolist()
    ([[1, 3], [2, 6], [5, 7]], [0, 4, 8])
    """
    n, E = mesh.n_vertices, mesh.n_edges
    a, b = mesh.edges[:, 0], mesh.edges[:, 1]
    diag = np.arange(n, dtype=np.int64)
    rows = np.concatenate([a, b, diag])
    cols = np.concatenate([b, a, diag])
    perm = np.lexsort((cols, rows))
    slot = np.empty_like(perm)
    slot[perm] = np.arange(len(perm))
    edge_slots = np.stack([slot[:E], slot[E:2 * E]], axis=1)
    sorted_rows = rows[perm]
    return LaplacianPattern(
        indptr=np.searchsorted(sorted_rows, np.arange(n + 1)).astype(np.int32),
        indices=cols[perm].astype(np.int32), rows=sorted_rows,
        edge_slots=edge_slots, diag_slots=slot[2 * E:],
        corner_slots=np.ascontiguousarray(edge_slots[mesh.face_edges]))

