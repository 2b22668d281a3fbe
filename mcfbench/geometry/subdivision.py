"""Loop subdivision of a closed triangle mesh and its limit surface.

A refinement series of one smooth surface from a coarse real mesh: level
``k`` is ``k`` steps of Loop subdivision (Loop 1987, Sect. 3.1) followed by
the limit mask, which moves every vertex to its position on the limit surface
the input mesh controls. Level 0 is the input mesh with its vertices moved to
the limit as well, so every level samples the same smooth surface (the mesh
size halves per level, the surface stays).

One Loop step (each triangle into four; Loop 1987; Warren and Weimer 2002,
Sect. 7.3):

* a new vertex on edge ``ab`` with opposite vertices ``c``, ``d``:
  ``3/8 (a + b) + 1/8 (c + d)``;
* an old vertex ``v`` of valence ``n`` with neighbours ``v_j``:
  ``(1 - n beta_n) v + beta_n sum_j v_j``, with Loop's
  ``beta_n = (1/n) (5/8 - (3/8 + cos(2 pi / n) / 4)^2)``.

The limit mask (Loop 1987, Sect. 3.3; Hoppe et al. 1994, "Piecewise smooth
surface reconstruction", Appendix; Stam 1998): ``v_inf = (1 - n chi) v +
chi sum_j v_j`` with ``chi = 1 / (n + 3 / (8 beta_n))``. Derivation: by
symmetry the left eigenvector of eigenvalue 1 of the step restricted to the
1-ring ``(v, v_1, ..., v_n)`` is ``(a, b, ..., b)``; its ``v`` component
gives ``a (1 - n beta) + n b 3/8 = a``, i.e. ``b = 8 beta a / 3`` (the
``v_j`` component, ``a beta + 5/8 b = b``, says the same), and ``a + n b = 1``
gives ``b = chi``. For ``n = 6`` (``beta = 1/16``) this is the regular
mask ``1/2, 1/12``. The test checks the eigenvector property itself: the limit
position of a vertex does not change when the mesh is subdivided first.

libigl's ``igl.loop`` is not used: it weights old vertices with Warren's
simplified ``beta = 3 / (8 n)`` (``3/16`` for ``n = 3``), not Loop's
``beta_n``, and the limit mask must use the ``beta`` of the steps it
continues (``tests/mcfbench/geometry/test_subdivision.py`` shows the difference).

Everything is sparse matrices on the unique edges: no loop over vertices or
edges. Only closed surfaces (every edge in two triangles): a boundary needs
the crease rules, which the real-mesh problems do not.
"""

import numpy as np
import scipy.sparse as sp


def loop_beta(valence):
    """Loop's weight ``beta_n`` of each neighbour of an old vertex of valence ``n``.

    Parameters
    ----------
    valence : (n,) int array

    Returns
    -------
    (n,) float array
    """
    n = np.asarray(valence, dtype=float)
    return (5.0 / 8.0 - (3.0 / 8.0 + np.cos(2.0 * np.pi / n) / 4.0) ** 2) / n


def loop_limit_weight(valence):
    """The limit mask's neighbour weight ``chi = 1 / (n + 3 / (8 beta_n))``; the
    vertex keeps ``1 - n chi``."""
    n = np.asarray(valence, dtype=float)
    return 1.0 / (n + 3.0 / (8.0 * loop_beta(n)))


def _edges(faces, n):
    """Unique edges of a closed mesh and, per half-edge (corner ``c`` of triangle
    ``t``: edge from corner ``c`` to ``c + 1``), its edge index and opposite vertex.

    Raises
    ------
    ValueError
        The mesh has an edge not shared by exactly two triangles.
    """
    F = np.asarray(faces, dtype=np.int64)
    a, b = F.ravel(), np.roll(F, -1, axis=1).ravel()
    opposite = np.roll(F, -2, axis=1).ravel()
    key = np.minimum(a, b) * n + np.maximum(a, b)
    unique, edge_of, count = np.unique(key, return_inverse=True, return_counts=True)
    if (count != 2).any():
        raise ValueError(f"Loop subdivision needs a closed surface: {int((count == 1).sum())} "
                         f"boundary edge(s), {int((count > 2).sum())} non-manifold edge(s)")
    return unique // n, unique % n, edge_of.reshape(F.shape), opposite


def _one_ring(ea, eb, n):
    """The vertex adjacency matrix (``(n, n)`` CSR, ones) and the valences of the
    edges ``(ea, eb)``."""
    adjacency = sp.coo_matrix((np.ones(2 * len(ea)), (np.r_[ea, eb], np.r_[eb, ea])),
                              shape=(n, n)).tocsr()
    return adjacency, np.bincount(np.r_[ea, eb], minlength=n)


def loop_step(vertices, faces):
    """One Loop subdivision step of a closed triangle mesh.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array, consistently oriented, closed

    Returns
    -------
    V : (n + e, 3) float array
        The ``n`` old vertices moved by Loop's vertex rule, then one new vertex
        per edge (``e`` edges, in the order of their sorted vertex pairs).
    F : (4 m, 3) int64 array
        Each triangle ``(i, j, k)`` becomes ``(i, ij, ki)``, ``(j, jk, ij)``,
        ``(k, ki, jk)``, ``(ij, jk, ki)``, oriented as the input.
    """
    V = np.asarray(vertices, dtype=float)
    F = np.asarray(faces, dtype=np.int64)
    n = len(V)
    ea, eb, edge_of, opposite = _edges(F, n)
    e = len(ea)
    adjacency, valence = _one_ring(ea, eb, n)
    beta = loop_beta(valence)
    old = sp.diags(1.0 - valence * beta) + sp.diags(beta) @ adjacency
    # each edge gets 3/16 of both ends and 1/8 of the opposite vertex from
    # each of its two half-edges: 3/8 (a + b) + 1/8 (c + d)
    rows = np.tile(edge_of.ravel(), 3)
    cols = np.r_[F.ravel(), np.roll(F, -1, axis=1).ravel(), opposite]
    weights = np.r_[np.full(2 * F.size, 3.0 / 16.0), np.full(F.size, 1.0 / 8.0)]
    new = sp.coo_matrix((weights, (rows, cols)), shape=(e, n))
    S = sp.vstack([old, new]).tocsr()
    ij, jk, ki = (n + edge_of[:, c] for c in range(3))
    i, j, k = F.T
    F2 = np.concatenate([np.c_[i, ij, ki], np.c_[j, jk, ij], np.c_[k, ki, jk], np.c_[ij, jk, ki]])
    return S @ V, F2


def loop_limit(vertices, faces):
    """Every vertex moved to its position on the Loop limit surface (the mask
    ``(1 - n chi) v + chi sum_j v_j``, see the module docstring).

    Returns
    -------
    (n, 3) float array
    """
    V = np.asarray(vertices, dtype=float)
    ea, eb, _, _ = _edges(faces, len(V))
    adjacency, valence = _one_ring(ea, eb, len(V))
    chi = loop_limit_weight(valence)
    return (1.0 - valence * chi)[:, None] * V + chi[:, None] * (adjacency @ V)


def loop_limit_level(vertices, faces, level):
    """Level ``level`` of the refinement series: ``level`` Loop steps, then the
    limit mask (level 0: the input's vertices moved to the limit).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array, closed and consistently oriented
    level : int >= 0

    Returns
    -------
    V : (n_k, 3) float array
        ``n_k = n_{k-1} + e_{k-1}`` vertices (``e`` edges of the level before).
    F : (4^k m, 3) int64 array
    """
    if int(level) != level or level < 0:
        raise ValueError(f"level must be a whole number >= 0, got {level!r}")
    V, F = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    for _ in range(int(level)):
        V, F = loop_step(V, F)
    return loop_limit(V, F), F
