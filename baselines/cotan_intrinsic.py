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

Where the mesh already is its own intrinsic Delaunay triangulation and no
triangle is mollified, the package's operators are the mesh's cotangent
stiffness and barycentric mass (Bobenko and Springborn: the intrinsic Delaunay
triangulation is reached by flipping the edges of negative weight, and there
are none), which the compiled assembly of :class:`baselines.cotan.CotanAssembler`
gives in a fraction of the package's time: a step takes them when
:func:`is_intrinsic_delaunay` says so (every mesh edge weight ``(cot alpha + cot
beta) / 2`` and a boundary edge's ``cot alpha`` (its two sheets of the tufted
cover meet at the same angle) above the package's flipping threshold, every
triangle twice the mollification's margin away from degenerate), the package's
call otherwise (baselines/README.md,
"Deviations and interpretations").

The step is solved in the row-scaled form (C3), ``(I + tau diag(1/M) L) X^n
= X^{n-1}`` (:func:`baselines.cotan.row_scaled_matrix`), with identity rows
at boundary vertices (held fixed, Dirichlet). The state, the checks of a state (on the mesh's
own triangles: an inverted or collapsed mesh triangle ends a run as for
``cotan``) and the L2 weights (the mesh's barycentric lumped mass, the same
total area) are those of :class:`baselines.cotan.VertexFlow`.
"""

import numpy as np
import robust_laplacian

from .cotan import VertexFlow, row_scaled_matrix

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


def is_intrinsic_delaunay(vertices, mesh, L_data, edge_slots, mollify=MOLLIFY):
    """Whether :func:`intrinsic_operators` of ``vertices`` are the mesh's own cotangent
    stiffness ``L_data`` and barycentric mass.

    True when every mesh edge has a weight ``-L_ab >= FLIP_BELOW / 4`` (no edge of
    the tufted cover is flipped, :data:`FLIP_BELOW`, with a margin for round-off:
    an interior edge of the cover has the mesh edge's two opposite angles, the
    weight ``-L_ab``; a boundary edge twice its one angle, ``-2 L_ab``) and
    every triangle satisfies its triangle inequalities by at least ``2 delta``,
    ``delta = mollify`` x the mean edge length (the package's mollification
    ``epsilon`` is then 0, with a margin for its own round-off in the lengths).

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
    bool
    """
    if not np.all(L_data[edge_slots[:, 0]] <= -0.25 * FLIP_BELOW):
        return False
    lengths = np.linalg.norm(vertices[mesh.edges[:, 1]] - vertices[mesh.edges[:, 0]], axis=1)
    sides = lengths[mesh.face_edges]                                   # (m, 3)
    slack = sides.sum(axis=1) - 2.0 * sides.max(axis=1)   # la + lb - lc, lc the longest
    return bool(slack.min() > 2.0 * mollify * lengths.mean())


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
        """Systems assembled with the mesh's operators (:func:`is_intrinsic_delaunay`)."""
        super().__init__(vertices, faces, tau, mass="barycentric")

    def operators(self, at=None):
        """``(L, mass)`` of :func:`intrinsic_operators` at the state ``at`` (3, n)
        (default the current one): the mesh's cotangent stiffness (CSR) and
        barycentric mass where :func:`is_intrinsic_delaunay`, the package's otherwise."""
        at = self._X if at is None else at
        g = self._delaunay_geometry(at)
        if g is not None:
            return self.assembler.laplacian(g.L_data), g.mass
        return intrinsic_operators(at.T, self.faces, self.mollify)

    def _delaunay_geometry(self, at):
        """The mesh's :class:`baselines.cotan.SurfaceGeometry` at ``at`` when its
        operators are the intrinsic ones (:func:`is_intrinsic_delaunay`, no degenerate
        triangle), else None."""
        g = self.geometry_at(at)
        if g.degenerate == 0 and is_intrinsic_delaunay(
                at.T, self.mesh, g.L_data, self.assembler.pattern.edge_slots, self.mollify):
            return g
        return None

    def _system(self, at, base, dt):
        """``A = I + dt diag(1/M*) L*`` (C3) of the intrinsic operators at ``at``, CSR,
        rows of boundary vertices = identity; ``b = B``."""
        g = self._delaunay_geometry(at)
        if g is not None:
            self.delaunay_steps += 1
            return self.assembler.row_scaled(g.L_data, g.mass, dt, self.fixed), base
        L, mass = intrinsic_operators(at.T, self.faces, self.mollify)
        return row_scaled_matrix(L, mass, dt, self.fixed), base
