"""The parametric finite element scheme of Barrett, Garcke and Nuernberg (BGN).

J. W. Barrett, H. Garcke, R. Nuernberg, "On the parametric finite element
approximation of evolving hypersurfaces in R^3", J. Comput. Phys. 227
(2008) 4281-4307, Section 2, the scheme for mean curvature flow. Given the
polyhedral surface ``Gamma^m`` (vertices ``X^m``), find ``X^{m+1}`` (vector
P1) and ``kappa^{m+1}`` (scalar P1) such that for all scalar ``chi`` and
vector ``eta`` (P1 on ``Gamma^m``)::

    < (X^{m+1} - X^m) / tau, chi omega^m >_h - < kappa^{m+1}, chi >_h = 0      (B1)
    < kappa^{m+1} omega^m, eta >_h + < grad_s X^{m+1}, grad_s eta > = 0       (B2)

with ``<u, v>_h = 1/3 sum_sigma |sigma| sum_{k in sigma} u(q_k) v(q_k)``
the mass-lumped inner product on ``Gamma^m`` and ``omega^m`` the
mass-lumped vertex normal::

    omega_k = sum_{sigma ni k} |sigma| nu_sigma / sum_{sigma ni k} |sigma|    (B3)

(NOT normalised, ``|omega_k| <= 1``; normalising it gives another scheme).
Sign: (B2) is the weak form of ``kappa nu = Delta_s X`` (``int grad X .
grad eta = - int Delta_s X . eta``), and (B1) of ``V . nu = kappa``,
together ``V . nu = nu . Delta_s X``: mean curvature flow (a sphere of
radius r has ``kappa = -2/r`` and shrinks).

Elimination of ``kappa`` (derived here)
--------------------------------------
Let ``phi_k`` be the hat functions, ``m_k = <1, phi_k>_h =
1/3 sum_{sigma ni k} |sigma|`` the lumped (barycentric) mass and ``A_kj =
int grad_s phi_j . grad_s phi_k`` the cotangent stiffness (``L`` of
:mod:`baselines.cotan`, positive semi-definite). Lumping gives
``<v . nu^m, phi_k>_h = 1/3 sum_{sigma ni k} |sigma| v_k . nu_sigma =
m_k v_k . omega_k``, so

* (B1) with ``chi = phi_k``: ``m_k omega_k . (X_k^{m+1} - X_k^m) / tau =
  m_k kappa_k``, i.e. ``kappa_k = omega_k . (X_k^{m+1} - X_k^m) / tau``;
* (B2) with ``eta = phi_k e_c``: ``m_k kappa_k omega_{k,c} + sum_j A_kj
  X_{j,c}^{m+1} = 0``; substituting ``kappa_k``::

    (A + P / tau) X^{m+1} = P X^m / tau,    P = diag_k(m_k omega_k omega_k^T)  (B4)

  a 3n x 3n system, ``A`` acting on each coordinate (block diagonal).

``A + P/tau`` is symmetric positive semi-definite; its kernel is
``{X = const c : omega_k . c = 0 for all k}``, trivial on a closed surface
(the ``omega_k`` span R^3): there it is positive definite, although ``P``
has rank 1 per vertex (tangential motion is fixed only through ``A``).
Boundary vertices (open surfaces) are held fixed: their three rows are
identity rows with right-hand side ``X^m`` (the matrix is then no longer
symmetric).

Unknowns are ordered by components, ``[x_1..x_n, y_1..y_n, z_1..z_n]``, so
the (3, n) blocks ``b`` and ``x0`` of the shared solver ravel (C order) to
this vector and its iteration count means what it means for the other
schemes (one solve of all 3n unknowns).

Row scaling (``scaling="mass"``, default): row ``(c, k)`` is multiplied by
``tau / m_k``, i.e. the system solved is ``(diag(tau/m) A + Omega) X^{m+1}
= Omega X^m`` with ``Omega = diag_k(omega_k omega_k^T)``: the same
solution (an invertible row scaling changes neither the solution nor the
scheme), the same form ``I``-like diagonal as the row-scaled cotangent
system (C3) and fewer iterations (measured in ``baselines/README.md``).
``scaling="none"`` passes the symmetric (B4) itself.
"""

import numpy as np
import scipy.sparse as sp

from kept_factor.threads import for_threads

from .kernels import bgn_system
from .laplacian import with_values
from .vertex_flow import VertexFlow

SCALINGS = ("mass", "none")


def block_pattern(pattern):
    """CSR pattern of the (3n, 3n) BGN matrix (B4) from that of ``L``.

    Row ``c n + i`` holds, in column order, ``d n + i`` for ``d < c``, the
    entries ``c n + j`` of row ``i`` of ``L``, then ``d n + i`` for ``d > c``
    (the layout :func:`baselines.kernels.bgn_system` writes).

    Parameters
    ----------
    pattern : baselines.mesh.LaplacianPattern

    Returns
    -------
    indptr : (3n + 1,) int32 array
    indices : (3 (nnz + 2 n),) int32 array
    """
    n, nnz = pattern.shape[0], pattern.nnz
    block = nnz + 2 * n
    indptr_L = pattern.indptr.astype(np.int64)
    lengths = np.diff(indptr_L)
    starts = indptr_L[:-1] + 2 * np.arange(n)                  # within one block
    indptr = np.concatenate([c * block + starts for c in range(3)] + [[3 * block]])
    indices = np.empty(3 * block, dtype=np.int64)
    row_of = pattern.rows
    i = np.arange(n)
    for c in range(3):
        # the entries of L, shifted by the c couplings in front of them
        indices[c * block + np.arange(nnz) + 2 * row_of + c] = c * n + pattern.indices
        for d in range(3):
            if d == c:
                continue
            offset = d if d < c else lengths + d - 1
            indices[c * block + starts + offset] = d * n + i
    return indptr.astype(np.int32), indices.astype(np.int32)


class BGNFlow(VertexFlow):
    """BGN mean curvature flow (B1)-(B2), solved as (B4), of one triangulated surface.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``.
    faces : (m, 3) int array
        Consistently oriented triangles (the normals ``nu_sigma`` follow
        the orientation; the scheme does not depend on which side).
    tau : float
    scaling : {"mass", "none"}
        Row scaling of (B4) passed to the solver (see module docstring).
    threads : int
        Threads of the assembly and the checks (:class:`baselines.vertex_flow.VertexFlow`).

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> A, b = BGNFlow(V, F, 0.01, scaling="none").system()
    >>> A.shape, b.shape, bool(abs(A - A.T).max() < 1e-14)
    ((12, 12), (3, 4), True)
    """

    alpha = 0.0
    """The weight of the identity in the matrix of the normal velocity, ``Omega_k =
    alpha I + (1 - alpha) omega_k omega_k^T``: 0 here (B4), DeTurck's ``alpha`` (D4)."""

    def __init__(self, vertices, faces, tau, *, scaling="mass", threads=1):
        if scaling not in SCALINGS:
            raise ValueError(f"unknown scaling {scaling!r}; choose one of {', '.join(SCALINGS)}")
        self.scaling = scaling
        super().__init__(vertices, faces, tau, mass="barycentric", threads=threads)
        self._indptr, self._indices = block_pattern(self.assembler.pattern)
        n = 3 * self.mesh.n_vertices                 # a step's matrix: with_values of it
        self._pattern = sp.csr_matrix((np.zeros(len(self._indices)), self._indices,
                                       self._indptr), shape=(n, n))

    @property
    def omega(self):
        """(n, 3) mass-lumped vertex normals (B3) of the current surface."""
        return self._normals(self.geometry)

    def _normals(self, geometry):
        """(n, 3) the normals (B3) of the surface of ``geometry``."""
        return self.assembler.normals(geometry.area_vectors, self.threads)

    def _laplacian_data(self, geometry):
        """Values of the stiffness in (B4) (``A``, in the pattern of ``L``) at the surface
        of ``geometry``; :mod:`baselines.deturck` adds its advection."""
        return geometry.L_data

    def laplacian(self):
        """The cotangent stiffness ``A`` (one coordinate) of the current surface, CSR."""
        return self.assembler.laplacian(self.geometry_at(self._X).L_data)

    def system(self, at=None, base=None, dt=None, *, scaling=None):
        """``(A, b)`` of (B4) with ``Gamma^m`` the surface ``at``.

        The harness's integrators (``mcfbench.running.integrators``, (I1))
        replace ``X^m`` by the base state ``B`` in the difference quotient of
        (B1) and ``tau`` by ``dt``; the operators (``A``, ``omega``, the lumped
        mass) are those of ``Gamma^m = at``. Default: the scheme's own step
        from the current state.

        Parameters
        ----------
        at, base : (3, n) float arrays, optional
            ``X*`` and ``B`` (default ``X^m``).
        dt : float, optional
            Default ``tau``.
        scaling : {"mass", "none"}, optional
            Default: the flow's.

        Returns
        -------
        A : (3n, 3n) scipy.sparse.csr_matrix
            ``A + P/dt`` (``"none"``) or ``diag(dt/m) A + Omega``
            (``"mass"``), unknowns by components; Dirichlet rows identity.
        b : (3, n) float array
            ``P B / dt`` (``"none"``) or ``Omega B`` (``"mass"``); ``B`` at
            Dirichlet vertices.
        """
        scaling = self.scaling if scaling is None else scaling
        if scaling not in SCALINGS:
            raise ValueError(f"unknown scaling {scaling!r}; choose one of {', '.join(SCALINGS)}")
        return super().system(at, base, dt, scaling=scaling)

    def _system(self, at, base, dt, scaling):
        g, p, n = self.geometry_at(at), self.assembler.pattern, self.mesh.n_vertices
        data = np.empty(len(self._indices))
        b = np.empty((3, n))
        for_threads(bgn_system, self.threads)(
            self._laplacian_data(g), p.indptr, p.diag_slots, g.mass, self._normals(g),
            np.ascontiguousarray(base), dt, self.fixed, scaling == "mass", self.alpha, data, b)
        return with_values(self._pattern, data), b
