"""Building blocks of the surface generators: rotations, quad grids, surfaces of
revolution, welding coincident vertices, orientation and the closed-manifold check."""

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from mcfbench.geometry.metrics import triangle_normals


def rotation(ax, ay, az):
    """(3, 3) rotation ``R_z(az) R_y(ay) R_x(ax)``."""
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


DIAGONALS = ("alternating", "parallel", "twisted")


def quad_grid(n_u, n_v, wrap_u, wrap_v, diagonals):
    """Triangles of a grid of quads, counter-clockwise in ``(u, v)``.

    Vertex ``(i, j)`` is ``j n_u + i``; ``wrap_u``/``wrap_v`` join the last
    column/row to the first. Quad ``(i, j)`` has corners ``p = (i, j)``,
    ``q = (i+1, j)``, ``r = (i+1, j+1)``, ``s = (i, j+1)`` and is cut along
    ``p-r`` (``"parallel"``; ``"alternating"`` when ``i + j`` is even) into
    ``(p, q, r), (p, r, s)``, else along ``q-s`` into ``(p, q, s), (q, r, s)``
    (``"twisted"``; ``"alternating"`` when odd). Returns the ``(2 n_quads, 3)``
    int64 array: all first triangles (quads in row-major order), then all
    second ones.
    """
    nu, nv = n_u if wrap_u else n_u - 1, n_v if wrap_v else n_v - 1
    j, i = np.meshgrid(np.arange(nv), np.arange(nu), indexing="ij")
    i, j = i.ravel(), j.ravel()
    i1, j1 = (i + 1) % n_u, (j + 1) % n_v
    p, q, r, s = j * n_u + i, j * n_u + i1, j1 * n_u + i1, j1 * n_u + i
    if diagonals == "parallel":
        along_pr = np.ones(len(p), bool)
    elif diagonals == "twisted":
        along_pr = np.zeros(len(p), bool)
    else:
        along_pr = (i + j) % 2 == 0
    first = np.where(along_pr[:, None], np.column_stack([p, q, r]), np.column_stack([p, q, s]))
    second = np.where(along_pr[:, None], np.column_stack([p, r, s]), np.column_stack([q, r, s]))
    return np.concatenate([first, second]).astype(np.int64)


def revolution(rho, z, counts, scale=1.0):
    """Surface of revolution about the ``z`` axis through rings of vertices.

    Ring ``k`` (from the top) has ``counts[k]`` vertices
    ``scale * (rho_k cos phi, rho_k sin phi, z_k)``,
    ``phi = 2 pi j / counts[k]``; a ring of one vertex with ``rho_k = 0`` is a
    pole. Consecutive rings are zipped by :func:`zip_rings`; normals point
    away from the axis when ``z`` decreases along the rings.
    """
    counts = np.asarray(counts, dtype=np.int64)
    start = np.r_[0, np.cumsum(counts)[:-1]]
    ring = np.repeat(np.arange(len(counts)), counts)
    phi = 2.0 * np.pi * (np.arange(counts.sum()) - start[ring]) / counts[ring]
    rho, z = np.asarray(rho, float)[ring], np.asarray(z, float)[ring]
    V = scale * np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
    F = np.concatenate([zip_rings(start[k], counts[k], start[k + 1], counts[k + 1])
                        for k in range(len(counts) - 1)])  # one block per pair of rings
    return V, F


def zip_rings(s_in, m, s_out, M):
    """Triangles between two coaxial rings, swept counter-clockwise.

    The inner ring has ``m`` vertices ``s_in + i`` at azimuths
    ``2 pi i / m``, the outer one ``M`` vertices ``s_out + j`` at
    ``2 pi j / M``. Each triangle advances one ring by one vertex; the
    advances are taken in the order of the azimuth of the vertex they reach
    (ties: inner first), giving ``m + M`` triangles, less the one that
    would repeat a vertex when a ring is a single pole.
    """
    key = np.r_[np.arange(1, m + 1) / m, np.arange(1, M + 1) / M]
    order = np.argsort(key, kind="stable")
    outer = order >= m
    i = np.r_[0, np.cumsum(~outer)][:-1]  # positions before each advance
    j = np.r_[0, np.cumsum(outer)][:-1]
    nxt = np.where(outer, s_out + (j + 1) % M, s_in + (i + 1) % m)
    # (inner, outer, next) is counter-clockwise seen from outside
    tri = np.column_stack([s_in + i % m, s_out + j % M, nxt]).astype(np.int64)
    return tri[(tri[:, 0] != tri[:, 2]) & (tri[:, 1] != tri[:, 2])]


def orient_away_from(V, F, centre):
    """Reverse the triangles whose normal points towards ``centre``."""
    away = np.einsum("ij,ij->i", triangle_normals(V, F), V[F].mean(axis=1) - centre)
    return np.where((away < 0)[:, None], F[:, ::-1], F)


def orient_along(V, F, direction):
    """Reverse the triangles whose normal points against ``direction``."""
    return np.where((triangle_normals(V, F) @ direction < 0)[:, None], F[:, ::-1], F)


def weld_vertices(V, F, tol=0.0):
    """Weld vertices closer than ``tol``; drop degenerate, folded and unused elements.

    Each cluster of vertices joined by pairs closer than ``tol`` (and of
    coincident vertices) becomes its first vertex. Triangles repeating a
    vertex or of zero area are dropped, so are all copies of a triangle
    whose vertex set occurs more than once, then unreferenced vertices.
    Vertices and triangles keep their order.
    """
    n = len(V)
    if tol > 0:  # clusters of the graph of pairs closer than tol (coincident ones too)
        from scipy.spatial import cKDTree  # on first use: scipy.spatial takes 0.1-0.4 s

        pairs = cKDTree(V).query_pairs(tol, output_type="ndarray")
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, cluster = connected_components(graph, directed=False)
    else:  # clusters of coincident vertices
        _, cluster = np.unique(V, axis=0, return_inverse=True)
        cluster = cluster.ravel()
    first = np.full(cluster.max() + 1, n)
    np.minimum.at(first, cluster, np.arange(n))
    size = np.bincount(cluster)
    V = V.copy()
    V[first] = np.column_stack([np.bincount(cluster, weights=V[:, k]) / size for k in range(3)])
    F = first[cluster][F]
    area2 = np.linalg.norm(triangle_normals(V, F), axis=1)
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0]) & (area2 > 0)]
    _, triple, count = np.unique(np.sort(F, axis=1), axis=0,
                                 return_inverse=True, return_counts=True)
    F = F[count[triple.ravel()] == 1]
    used = np.zeros(n, bool)
    used[F.ravel()] = True
    new = np.cumsum(used) - 1
    return V[used], new[F].astype(np.int64)


def check_closed_manifold(V, F):
    """Raise unless the triangles form a closed, consistently oriented 2-manifold
    (:func:`mcfbench.geometry.mesh.summarize`, which validates first, and no boundary loop)."""
    from mcfbench.geometry.mesh import MeshError, summarize

    try:
        loops = summarize(V, F).boundary_loops
    except MeshError as err:
        raise ValueError(f"marching cubes gave an open or non-manifold mesh: {err}; "
                         "enlarge the box or refine the grid") from None
    if loops:
        raise ValueError(f"marching cubes gave an open or non-manifold mesh: {loops} "
                         "boundary loop(s); enlarge the box or refine the grid")
