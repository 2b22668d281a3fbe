"""The cotangent scheme on the intrinsic Delaunay triangulation (Sharp and Crane 2020).

Dziuk's semi-implicit scheme (C1) of :mod:`baselines.cotan`,

    (M^{n-1} + tau L^{n-1}) X^n = M^{n-1} X^{n-1},

with ``L`` and ``M`` the cotangent stiffness and the lumped mass of the
*intrinsic Delaunay triangulation* of the surface ``X^{n-1}`` instead of
those of its mesh: N. Sharp, K. Crane, "A Laplacian for Nonmanifold Triangle
Meshes", Computer Graphics Forum 39(5) (SGP 2020), the "tufted Laplacian":
the cotangent Laplacian of an intrinsic Delaunay triangulation, reached by
edge flips on the intrinsic edge lengths (Bobenko and Springborn, Discrete
Comput. Geom. 38 (2007)), of the "tufted cover" of the mesh, after an
intrinsic mollification of near-degenerate triangles. On a closed manifold
mesh the tufted cover is two copies of the surface glued along its edges and
the tufted Laplacian is the intrinsic Delaunay Laplacian of the surface; on a
mesh with boundary the two copies are also glued along the boundary, whose
edges may then flip as well (the paper's nonnegative boundary weights). The
triangulation has the same vertices and the same piecewise flat metric as
the mesh but other edges wherever the mesh is not Delaunay (opposite angles
summing to more than pi), so that every edge weight ``(cot alpha + cot
beta) / 2`` is >= 0: ``L`` is an M-matrix. Both are built by the
``robust-laplacian`` package (``robust_laplacian.mesh_laplacian``, the
authors' implementation), anew at every step, at the state the integrator
chooses (``X*``, :mod:`mcfbench.running.integrators`).

Conventions of ``mesh_laplacian(V, F, mollify_factor)`` (checked by
``tests/baselines/test_cotan_intrinsic.py``): ``L`` is the positive
semi-definite weak Laplacian (``-igl.cotmatrix`` on a Delaunay mesh), ``M``
the diagonal *barycentric* lumped mass of the intrinsic triangulation (a
third of the areas of its triangles at each vertex; not the Voronoi mass),
so that on a Delaunay mesh the scheme is :class:`baselines.cotan.CotanFlow`
with ``mass="barycentric"`` (registry ``cotan``) to round-off.
``mollify_factor`` ``delta`` (relative to the mean edge length): every edge
length grows by the smallest ``epsilon >= 0`` with which every triangle
satisfies the triangle inequality by ``delta`` times the mean edge length
(the paper's intrinsic mollification); zero on a mesh without such
near-degenerate triangles.

Where the mesh already is the package's triangulation and no triangle is
mollified, the package's operators are the mesh's cotangent stiffness and
barycentric mass (Bobenko and Springborn: the intrinsic Delaunay triangulation
is reached by flipping the edges of negative weight, and there are none),
which the compiled assembly of :class:`baselines.laplacian.CotanAssembler` gives in
a fraction of the package's time; where one round of flips of edges with no
triangle in common reaches it, those flips are applied to the mesh's operators
(:func:`flipped_operators`). A step takes them when :func:`edges_to_flip` says
so, the package's call otherwise (baselines/README.md, "Deviations and
interpretations").

The step is solved in the row-scaled form (C3), ``(I + tau diag(1/M) L) X^n
= X^{n-1}`` (:func:`baselines.laplacian.row_scaled_matrix`), with identity rows
at boundary vertices (held fixed, Dirichlet). The state, the checks of a state (on the mesh's
own triangles: an inverted or collapsed mesh triangle ends a run as for
``cotan``) and the L2 weights (the mesh's barycentric lumped mass, the same
total area) are those of :class:`baselines.vertex_flow.VertexFlow`.
"""

import numpy as np
import robust_laplacian
import scipy.sparse as sp

from .laplacian import row_scaled_matrix
from .vertex_flow import VertexFlow

MOLLIFY = 1e-5
"""The package's default ``mollify_factor`` (baselines/README.md, "Deviations and
interpretations")."""
FLIP_BELOW = -1e-6
"""The package flips an edge of the tufted cover whose weight ``(cot alpha + cot beta) / 2``
is below this (geometry-central's ``flipToDelaunay``, ``delaunayEPS = 1e-6``; measured on
a planar quad: weight -8e-7 kept, -1.2e-6 flipped)."""


def intrinsic_operators(vertices, faces, mollify=MOLLIFY):
    """Stiffness and lumped mass of the intrinsic Delaunay triangulation.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    mollify : float
        ``mollify_factor`` of ``robust_laplacian.mesh_laplacian``, >= 0.

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix
        Symmetric, positive semi-definite, zero row sums, edge weights >= 0.
    mass : (n,) float array
        Positive, sums to the area.
    """
    L, M = robust_laplacian.mesh_laplacian(
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(faces, dtype=np.int64), float(mollify))
    return L.tocsr(), np.asarray(M.diagonal())


MARGIN = 1e-9
"""Distance from :data:`FLIP_BELOW` within which an edge weight is left to the package
(round-off could put its weight on the other side there)."""


def edges_to_flip(vertices, mesh, L_data, edge_slots, mollify=MOLLIFY):
    """The mesh edges the package flips, when one round of flips of edges with no
    triangle in common reaches its triangulation; None when that is not known.

    The package flips an edge of the tufted cover whose weight is below
    :data:`FLIP_BELOW`, then the edges around it whose weight fell below. An
    interior edge of the cover has the mesh edge's weight ``w = -L_ab``, a boundary
    edge twice it (its one angle on both sheets). None (the package is needed)
    when: a triangle is within twice the mollification's margin of degenerate
    (``la + lb - lc < 2 delta``, ``delta = mollify`` x the mean edge length: the
    package's ``epsilon`` would not be 0); a weight is within :data:`MARGIN` of the
    threshold; a boundary edge would flip; two edges to flip share a triangle.
    :func:`flipped_operators` checks the rest (no edge below the threshold after
    the round).

    Parameters
    ----------
    vertices : (n, 3) float array
    mesh : baselines.mesh.EdgeMesh
    L_data : (nnz,) float array
        The mesh's cotangent stiffness (C2) at ``vertices`` in the pattern whose
        edge entries are ``edge_slots`` (:class:`baselines.mesh.LaplacianPattern`).
    edge_slots : (E, 2) int array
    mollify : float

    Returns
    -------
    (k,) int array or None
        Edge numbers (rows of ``mesh.edges``); empty: the mesh is the package's
        triangulation, its operators are the mesh's own.
    """
    lengths = np.linalg.norm(vertices[mesh.edges[:, 1]] - vertices[mesh.edges[:, 0]], axis=1)
    sides = lengths[mesh.face_edges]                                   # (m, 3)
    slack = sides.sum(axis=1) - 2.0 * sides.max(axis=1)   # la + lb - lc, lc the longest
    if not slack.min() > 2.0 * mollify * lengths.mean():
        return None
    boundary = mesh.edge_faces[:, 1] < 0
    cover = np.where(boundary, 2.0, 1.0) * -L_data[edge_slots[:, 0]]
    if np.any(np.abs(cover - FLIP_BELOW) <= MARGIN) or np.any(cover[boundary] < FLIP_BELOW):
        return None
    flip = np.flatnonzero(cover < FLIP_BELOW)
    faces = mesh.edge_faces[flip].ravel()
    if len(faces) and np.bincount(faces).max() > 1:
        return None
    return flip


def flipped_operators(vertices, mesh, L, mass, flip):
    """``(L, mass)`` of the triangulation of ``mesh`` with the edges ``flip`` flipped
    (:func:`edges_to_flip`), or None when an edge of it is still below :data:`FLIP_BELOW`
    (or within :data:`MARGIN` of it; a boundary edge with twice its weight, as in the
    tufted cover) or a new edge is already one.

    Each edge ``(a, b)`` between the triangles ``(a, b, c)`` and ``(b, a, d)``
    becomes ``(c, d)``, of the length of the planar unfolding of the two
    (Bobenko-Springborn: ``|c - d|`` with ``c``, ``d`` laid out on either side
    of ``ab`` from the side lengths); the two triangles' cotangent weights (C2)
    and thirds of their areas (barycentric mass) are taken out of ``L`` and
    ``mass`` and those of ``(a, d, c)`` and ``(b, c, d)`` put in, all from
    side lengths (cotangent ``(l_j^2 + l_k^2 - l_i^2) / (4 area)``, Heron's area).

    Parameters
    ----------
    vertices : (n, 3) float array
    mesh : baselines.mesh.EdgeMesh
    L : (n, n) scipy.sparse.csr_matrix
        The mesh's cotangent stiffness.
    mass : (n,) float array
        Its barycentric lumped mass.
    flip : (k,) int array
        Edges, no two on one triangle.

    Returns
    -------
    (L, mass) : ((n, n) scipy.sparse.csr_matrix, (n,) float array) or None
    """
    n = len(vertices)
    a, b = mesh.edges[flip, 0], mesh.edges[flip, 1]
    f1, f2 = mesh.edge_faces[flip, 0], mesh.edge_faces[flip, 1]
    c = mesh.faces[f1, np.argmax(mesh.face_edges[f1] == flip[:, None], axis=1)]
    d = mesh.faces[f2, np.argmax(mesh.face_edges[f2] == flip[:, None], axis=1)]
    new_keys = np.sort(np.minimum(c, d) * n + np.maximum(c, d))
    keys = mesh.edges[:, 0] * n + mesh.edges[:, 1]                  # sorted (EdgeMesh)
    if np.any(np.diff(new_keys) == 0) or np.any(
            keys[np.minimum(np.searchsorted(keys, new_keys), len(keys) - 1)] == new_keys):
        return None

    def dist(p, q):
        return np.linalg.norm(vertices[p] - vertices[q], axis=1)

    ab, ac, bc, ad, bd = dist(a, b), dist(a, c), dist(b, c), dist(a, d), dist(b, d)
    xc = (ab ** 2 + ac ** 2 - bc ** 2) / (2.0 * ab)         # c above ab, d below
    xd = (ab ** 2 + ad ** 2 - bd ** 2) / (2.0 * ab)
    yc = np.sqrt(np.maximum(ac ** 2 - xc ** 2, 0.0))
    yd = np.sqrt(np.maximum(ad ** 2 - xd ** 2, 0.0))
    cd = np.hypot(xc - xd, yc + yd)
    # (triangle, its vertices, its sides opposite them, +1 added / -1 taken out)
    triangles = [((a, b, c), (bc, ac, ab), -1.0), ((b, a, d), (ad, bd, ab), -1.0),
                 ((a, d, c), (cd, ac, ad), 1.0), ((b, c, d), (cd, bd, bc), 1.0)]
    rows, cols, values, mass = [], [], [], mass.copy()
    for corners, opposite, sign in triangles:
        l2 = [side ** 2 for side in opposite]
        x, y, z = opposite
        area = 0.25 * np.sqrt(np.maximum((x + y + z) * (-x + y + z) * (x - y + z) * (x + y - z),
                                         0.0))                                   # Heron
        for k in range(3):
            p, q = corners[(k + 1) % 3], corners[(k + 2) % 3]
            w = sign * (l2[(k + 1) % 3] + l2[(k + 2) % 3] - l2[k]) / (8.0 * area)   # cot / 2
            rows += [p, q, p, q]
            cols += [q, p, p, q]
            values += [-w, -w, w, w]
            np.add.at(mass, corners[k], sign * area / 3.0)
    delta = sp.csr_matrix((np.concatenate(values), (np.concatenate(rows),
                                                    np.concatenate(cols))), shape=(n, n))
    L = (L + delta).tocsr()
    off = L.tocoo()
    rim = mesh.edges[mesh.edge_faces[:, 1] < 0]            # boundary: twice in the cover
    boundary = np.asarray(L[rim[:, 0], rim[:, 1]]).ravel() if len(rim) else np.zeros(0)
    if np.any(-off.data[off.row != off.col] < FLIP_BELOW + MARGIN) or np.any(
            -2.0 * boundary < FLIP_BELOW + MARGIN):
        return None
    return L, mass


class IntrinsicCotanFlow(VertexFlow):
    """Cotangent mean curvature flow (C1) with the intrinsic Delaunay Laplacian.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``.
    faces : (m, 3) int array
        Consistently oriented triangles of a manifold surface, closed or with
        boundary (boundary vertices keep their position).
    tau : float
        Time step.
    mollify : float
        ``mollify_factor`` of :func:`intrinsic_operators`, finite and >= 0.

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> A, b = IntrinsicCotanFlow(V, F, 0.01).system()
    >>> A.shape, b.shape
    ((4, 4), (3, 4))
    """

    def __init__(self, vertices, faces, tau, *, mollify=MOLLIFY):
        if not (np.isfinite(mollify) and mollify >= 0):
            raise ValueError(f"mollify must be a finite number >= 0, got {mollify!r}")
        self.mollify = float(mollify)
        self.delaunay_steps = 0
        """Systems assembled with the mesh's operators (:func:`edges_to_flip` empty)."""
        self.flipped_steps = 0
        """Systems assembled with one round of flips of the mesh (:func:`flipped_operators`)."""
        super().__init__(vertices, faces, tau, mass="barycentric")

    def operators(self, at=None):
        """``(L, mass)`` of :func:`intrinsic_operators` at the state ``at`` (3, n)
        (default the current one), CSR and (n,): from the mesh where it is the
        package's triangulation or one round of flips away from it
        (:func:`edges_to_flip`, :func:`flipped_operators`), the package's otherwise."""
        at = self._X if at is None else at
        found = self._mesh_operators(at)
        if found is None:
            return intrinsic_operators(at.T, self.faces, self.mollify)
        g, flipped = found
        return flipped if flipped is not None else (self.assembler.laplacian(g.L_data), g.mass)

    def _mesh_operators(self, at):
        """``(geometry, flipped)`` at ``at``: the mesh's :class:`baselines.laplacian.SurfaceGeometry`
        and, when the package flips edges, the ``(L, mass)`` of :func:`flipped_operators`
        (None when it flips none); None when the package is needed."""
        g = self.geometry_at(at)
        if g.degenerate:
            return None
        flip = edges_to_flip(at.T, self.mesh, g.L_data, self.assembler.pattern.edge_slots,
                             self.mollify)
        if flip is None or len(flip) == 0:
            return None if flip is None else (g, None)
        flipped = flipped_operators(at.T, self.mesh, self.assembler.laplacian(g.L_data),
                                    g.mass, flip)
        return None if flipped is None else (g, flipped)

    def _system(self, at, base, dt):
        """``A = I + dt diag(1/M*) L*`` (C3) of the intrinsic operators at ``at``, CSR,
        rows of boundary vertices = identity; ``b = B``."""
        found = self._mesh_operators(at)
        if found is None:
            L, mass = intrinsic_operators(at.T, self.faces, self.mollify)
            return row_scaled_matrix(L, mass, dt, self.fixed), base
        g, flipped = found
        if flipped is None:
            self.delaunay_steps += 1
            return self.assembler.row_scaled(g.L_data, g.mass, dt, self.fixed), base
        self.flipped_steps += 1
        return row_scaled_matrix(*flipped, dt, self.fixed), base
