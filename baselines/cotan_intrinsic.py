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
        super().__init__(vertices, faces, tau, mass="barycentric")

    def _needs_laplacian(self):
        return False          # the mesh's cotangent stiffness is never used

    def operators(self, at=None):
        """``(L, mass)`` of :func:`intrinsic_operators` at the state ``at`` (3, n)
        (default the current one)."""
        at = self._X if at is None else at
        return intrinsic_operators(at.T, self.faces, self.mollify)

    def _system(self, at, base, dt):
        """``A = I + dt diag(1/M*) L*`` (C3) of the intrinsic operators at ``at``, CSR,
        rows of boundary vertices = identity; ``b = B``."""
        L, mass = self.operators(at)
        return row_scaled_matrix(L, mass, dt, self.fixed), base
