"""Area-oriented tangential redistribution of the mesh vertices (cotangent scheme).

After K. Mikula, M. Remesikova, P. Sarkoci, D. Sevcovic, "Manifold evolution
with tangential redistribution of points", SIAM J. Sci. Comput. 36(4) (2014)
A1384-A1414 (the "volume-oriented", for surfaces area-oriented,
asymptotically uniform redistribution). The full text was not available to
us; the equations below are derived here from the construction the paper's
abstract and the notes in ``baselines/README.md`` describe, and every
interpretation is listed there under "Deviations and interpretations".

Continuous (derived)
--------------------
Let the surface move with ``X_t = V + v_T``, ``V`` the normal velocity
(``V = h`` for mean curvature flow, ``h = Delta_G X`` the mean curvature
vector) and ``v_T`` a tangential field. The area element obeys
``d/dt dA = (-h . V + div_G v_T) dA`` and the total area ``|G|``
obeys ``d/dt |G| = -int h . V dA`` (closed surface, or ``v_T . nu = 0`` on
the boundary). With ``q = N dA / (|G| du)`` the area density relative to a
uniform one (``du`` the parameter measure, total ``N``),
``d/dt ln q = -h . V + <h . V> + div_G v_T``, ``<.>`` the mean over ``G``.
Choosing ``v_T = grad_G psi`` with::

    Delta_G psi = h . V - <h . V> + omega (1 / q - 1)                      (R1)

gives ``d/dt q = omega (1 - q)``: ``q -> 1`` at the rate ``omega``
(asymptotically uniform area density), whatever the normal motion.
Compatibility: ``int (1/q - 1) dA = |G| - |G| = 0`` and the curvature terms
have mean zero, so (R1) is solvable; ``psi`` is unique up to a constant.

Discrete (this module)
----------------------
Covolume of vertex ``i`` = its lumped mass ``m_i`` (the scheme's own), so
``q_i = N m_i / |G|``, ``|G| = sum m_i``, ``N`` the number of vertices.
``Delta_G`` is the scheme's ``-M^{-1} L`` (``L`` the cotangent stiffness
(C2), ``M`` the lumped mass), ``h_i = -(M^{-1} L X)_i`` and, for MCF,
``h . V = |h_i|^2``. (R1) becomes::

    L psi = -M f,   f_i = |h_i|^2 - <|h|^2> + omega (|G| / (N m_i) - 1)    (R2)

``<|h|^2> = sum m_i |h_i|^2 / |G|``. ``sum_i m_i f_i = 0`` exactly, so
(R2) is consistent; the right-hand side is projected onto ``sum = 0``
(rounding), solved with ``psi_0`` pinned (:class:`PotentialSolver`) and
normalised by ``sum m_i psi_i = 0`` (the constant projected out; it does
not enter ``grad psi``).

How the tangential term enters the step (semi-implicit, advective)
------------------------------------------------------------------
A tangential velocity ``grad psi`` moves the parametrisation, so in the
equation of the positions it is the advection ``X_t = Delta_G X + grad psi
. grad_G X`` (for ``X`` the identity map ``grad_G X . w = w`` for tangent
``w``), which is::

    X_t = e^{-psi} div_G (e^{psi} grad_G X)                                (R3)

(expand the divergence). With ``psi = psi^n`` from the old state (R2) and
``X`` at the new level, this is a weighted Laplacian and is discretised
like the scheme's own: the flux of ``e^psi grad X`` through the dual edge
of ``ij`` is ``c_ij`` times the Scharfetter-Gummel mean of ``e^psi`` on the
edge (exact for ``psi`` linear along it: the flux ``q = e^psi X'`` is
constant, so ``X_j - X_i = q int e^{-psi}``), divided in row ``i`` by
``e^{psi_i}``::

    (X_i^{n+1} - X_i^n) / tau
        = (1/m_i) sum_j c_ij B(psi_i - psi_j) (X_j^{n+1} - X_i^{n+1}) + g_i
    B(x) = x / (e^x - 1)                                                   (R4)

``c_ij = (cot alpha_ij + cot beta_ij) / 2`` the cotangent weights (C2).
``B(-d) = 1 + d/2 + d^2/12 + ...`` (``d = psi_j - psi_i``): to first order
the Laplacian plus the centred advection ``(1/2 m_i) sum_j c_ij (psi_j -
psi_i)(X_j - X_i)`` (the discrete ``grad psi . grad X`` of the product
rule ``Delta(psi X) = psi Delta X + X Delta psi + 2 grad psi . grad X``);
for large ``|d|`` it is the upwind flux ``c_ij max(d, 0) (X_j - X_i)``
(:func:`drift_laplacian`; exact for a linear ``psi`` on a uniform line of
points, whatever ``tau``: ``B(-d) - B(d) = d``).

The drift moves points along chords, and its non-centred part has a normal
component of order ``h |grad psi| |II|``: its normal part at the old state is
added back explicitly (as the elimination (3.6) of the DDFV paper removes a
tangential part)::

    g_i = N_i N_i . ((L_psi - L) X^n)_i / m_i                              (R5)

(``N_i`` the unit area-weighted vertex normal; zero at fixed vertices).
Without it the pole-clustered sphere of the tests ends 3.7 x further from
the sphere than cotan (radius error 1.7e-2 against 4.7e-3); with it within
1.2 x (tested).

The edge Peclet number ``|psi_j - psi_i|`` is limited::

    d_ij -> min(max(d_ij, -P), P)      in the weights of (R4)               (R6)

(``peclet=P``, default :data:`PECLET`). On real meshes ``psi`` from (R2)
differs by 1-20 across an edge (median 0.6-1.5, up to 23 on the public
meshes: the ``h.V`` term at small features), i.e. a step would move points
by ``~0.1 d`` edge lengths; the limit caps that at ``~0.1 P`` and is inactive
on a smooth refinement series once ``h |grad psi| < P`` (the icosphere's
differences are 0.03 at level 2, 0.016 at level 3). ``P = 0.1`` was chosen by
measurement on the twelve public meshes (``baselines/README.md``).

Stability, for any ``tau``: ``B > 0``, so where the cotangent weights are
positive the matrix of (R4) is an M-matrix with row sums 1 (row-scaled form
(C3)): its inverse is nonnegative with row sums 1, every new point is a
convex combination of the old ones (a maximum principle for every
coordinate and direction), with no step restriction, clipped or not. Where
no difference is clipped, ``e^{psi_i} B(psi_i - psi_j) = (psi_i - psi_j)
e^{psi_i + psi_j} / (e^{psi_i} - e^{psi_j})`` is symmetric in ``ij``, so (R4)
times ``m_i e^{psi_i}`` is ``(M_psi + tau L_psi) X = M_psi (X^n + tau g)``
with ``L_psi`` symmetric positive semi-definite: with ``g = 0`` the step does
not increase the ``e^psi``-weighted Dirichlet energy, as Dziuk's step does not
increase the area. The explicit shift ``X^n + tau grad psi`` it
replaces has the stability limit of an explicit advection (``tau |grad
psi|`` against the edge length).

The tangential velocity at the vertices (:func:`tangential_velocity`, the
lumped L2 projection of the piecewise-constant gradient onto the tangent
plane of the area-weighted vertex normal) is the velocity of (R1) that
(R4) carries, kept for diagnostics and tests.
``target="triangle"`` (:func:`target_shares`) replaces ``1/N`` in (R2)
by the share of a mesh of equal-area triangles.

Fixed boundary: boundary vertices do not move (``V = 0`` and ``v_T = 0``
there, so ``h . V = 0`` in (R2)); ``psi`` takes the natural (Neumann)
condition ``d psi / d nu = 0`` (``L`` with its boundary rows, unmodified),
i.e. no point crosses the fixed boundary.
"""

import numpy as np
import scipy.sparse as sp

from kept_factor import KeptFactorSolver, as_csr, pinned

from .tangential_kernels import drift_weights, squared_curvature_normals, vertex_gradients

REDISTRIBUTIONS = (None, "area")
PECLET = 0.1
"""Default limit of the edge Peclet number ``|psi_j - psi_i|`` of (R6)."""
OMEGA = 10.0
"""Default relaxation rate of (R1): area ratios relax like ``exp(-omega t)``."""
POTENTIAL_RTOL = 1e-4
"""Relative residual of the potential's solve (:class:`PotentialSolver`)."""


def target_shares(faces, n, target="vertex"):
    """Target share ``w_i`` of the total area for each covolume, ``sum w_i = 1``.

    ``"vertex"``: ``1/N``, every covolume the same area (R2), the
    asymptotically uniform redistribution. ``"triangle"``: ``d_i / (3
    n_T)``, ``d_i`` the number of triangles at ``i``: the barycentric
    covolumes of a mesh whose triangles all have the same area (boundary
    vertices of a straight boundary get half, valence-5 vertices 5/6).

    Parameters
    ----------
    faces : (m, 3) int array
    n : int
    target : {"vertex", "triangle"}

    Returns
    -------
    (n,) float array
    """
    if target == "vertex":
        return np.full(n, 1.0 / n)
    if target == "triangle":
        return np.bincount(np.asarray(faces).ravel(), minlength=n) / (3.0 * len(faces))
    raise ValueError(f"unknown target {target!r}; choose 'vertex' or 'triangle'")


def redistribution_source(L, mass, X, fixed, omega, shares=None):
    """The right-hand side ``f`` of (R2), shape (n,), with ``sum m_i f_i = 0``.

    Parameters
    ----------
    L : (n, n) sparse matrix
    mass : (n,) float array
        Lumped mass ``m_i`` (covolume areas), all positive.
    X : (3, n) float array
    fixed : (n,) bool array
        Boundary vertices: no motion, ``h . V = 0``.
    omega : float
        Relaxation rate (``>= 0``).
    shares : (n,) float array, optional
        Target shares ``w_i`` (:func:`target_shares`); default ``1/N``:
        the term is ``omega (w_i |G| / m_i - 1)``.

    Returns
    -------
    (n,) float array
    """
    L = as_csr(L)
    hV = np.empty(len(mass))                            # |h_i|^2, h_i = -(L X)_i / m_i,
    squared_curvature_normals(L.indptr, L.indices,      # zero where m_i = 0 or fixed
                              np.asarray(L.data, dtype=np.float64),
                              np.asarray(X, dtype=np.float64),
                              np.asarray(mass, dtype=np.float64),
                              np.asarray(fixed, dtype=np.bool_), hV)
    area = mass.sum()
    f = hV - (mass * hV).sum() / area
    if omega:
        w = np.full(len(mass), 1.0 / len(mass)) if shares is None else shares
        f = f + omega * (w * area / mass - 1.0)
    return f


class PotentialSolver(KeptFactorSolver):
    """``psi`` of (R2) along a flow: ``L psi = -M f``, normalised to ``sum m_i psi_i = 0``.

    ``L`` is singular (kernel: the constants). The right-hand side is
    projected onto its range (``sum = 0``) and ``psi_0 = 0`` is pinned: the
    system ``A psi = b`` with ``A = P L P + e_0 e_0^T`` (``P`` zeroes entry 0;
    symmetric positive definite for a connected mesh; :func:`kept_factor.pinned`)
    and ``b_0 = 0``. The constant is then projected out.

    The systems of a flow, whose geometry moves by ``O(tau)`` a step, are
    solved with a kept factorisation (:class:`kept_factor.KeptFactorSolver`):
    sparse Cholesky, and conjugate gradients preconditioned with the kept
    factor, started from the linear extrapolation ``2 psi^{n-1} - psi^{n-2}``
    of the last two solutions, until ``|b - A x| <= rtol |b|``; ``A`` is
    factorised anew when that takes more than ``max_iterations``. Chosen by
    measurement (``benchmarks/bench_potential.py --solvers``, level 5 of the
    sphere, 10 242 vertices, CPU time per solve of a flow's sequence of
    systems, ``baselines/README.md``): 1.7 ms and about one CG iteration,
    against 5.6 ms for the iterative refinement of a kept sparse LU (SuperLU,
    2.4 LU solves) it replaces; algebraic multigrid (``pyamg``, smoothed
    aggregation, hierarchy kept) + CG 4.2 ms (3.4 V-cycles); Jacobi-CG 12 ms
    (120 iterations; ~1200 on sliver-rich meshes). Where ``A`` is not
    numerically positive definite the factorisation is a sparse LU (SuperLU)
    and the iteration a refinement.

    ``psi`` only sets a tangential velocity, so its tolerance is
    :data:`POTENTIAL_RTOL` = 1e-4 (it was 1e-7): an error of that size moves
    the points tangentially by ``1e-4`` of the redistribution's own
    displacement, and the extrapolated start meets it in most steps with no
    iteration (no factor solve): at level 5 of the sphere 0.43 CG iterations
    per step against 1.75; the Table 3.1 setting's errors (levels 1-5) change by
    at most 6e-7 of themselves, their orders and the smallest angle and largest
    aspect ratio not in the 4th decimal (``baselines/README.md``).

    Parameters
    ----------
    rtol : float
    max_iterations : int
    """

    def __init__(self, rtol=None, max_iterations=4):
        super().__init__(POTENTIAL_RTOL if rtol is None else rtol, max_iterations)

    def __call__(self, L, mass, f):
        """``psi`` (n,) for the stiffness ``L`` (n, n, symmetric positive
        semi-definite, kernel the constants), the masses and ``f`` (n,)."""
        b = -mass * f
        b -= b.mean()                                  # onto the range of L (rounding)
        n = len(b)
        if n < 2 or not np.any(b):
            return np.zeros(n)
        keep = np.ones(n)
        keep[0] = b[0] = 0.0                           # psi_0 = 0
        psi = self.solve(b, *pinned(L, keep), sequence="psi")
        return psi - (mass * psi).sum() / mass.sum()


def solve_potential(L, mass, f):
    """``psi`` of (R2) in one call: a fresh :class:`PotentialSolver` (a factorisation).

    Parameters
    ----------
    L : (n, n) sparse matrix
        Symmetric positive semi-definite, kernel the constants (connected mesh).
    mass, f : (n,) float arrays

    Returns
    -------
    (n,) float array
    """
    return PotentialSolver()(L, mass, f)


def tangential_velocity(vertices, faces, psi):
    """``v_T = grad psi`` at the vertices, (3, n) (:func:`baselines.tangential_kernels.vertex_gradients`).

    Returns
    -------
    alpha : (3, n) float array
    degenerate : int
        Zero-area triangles skipped.
    """
    V = np.ascontiguousarray(vertices, dtype=np.float64)
    alpha = np.empty((len(V), 3))
    degenerate, _ = vertex_gradients(V, np.ascontiguousarray(faces, dtype=np.int64),
                                     np.ascontiguousarray(psi, dtype=np.float64), alpha)
    return alpha.T, degenerate


def drift_laplacian(L, psi, peclet=np.inf, X=None):
    """The stiffness of (R4): ``-e^{-psi} div(e^psi grad .)`` times the lumped mass.

    Parameters
    ----------
    L : (n, n) scipy.sparse.csr_matrix
        Cotangent stiffness (C2) with its diagonal stored: off-diagonal
        ``-c_ij``, zero row sums.
    psi : (n,) float array
        The potential (R2) of the old state.
    peclet : float
        Largest ``|psi_j - psi_i|`` an edge's weight sees (R6): the differences
        are clipped to ``[-peclet, peclet]``.
    X : (3, n) float array, optional
        Positions whose drift ``(L_psi - L) X`` (R5) is wanted too.

    Returns
    -------
    L_psi : (n, n) scipy.sparse.csr_matrix
        Same pattern (its ``indices`` and ``indptr``, shared); off-diagonal
        ``-c_ij B(psi_i - psi_j)`` (``B`` the Bernoulli function
        :func:`baselines.tangential_kernels.bernoulli_weight`), diagonal the negated sum
        of its row's off-diagonal entries (zero row sums): one compiled pass
        (:func:`baselines.tangential_kernels.drift_weights`). Not symmetric, but where no
        difference is clipped ``diag(e^psi) L_psi`` is (``psi`` constant: ``L``
        itself).
    drift : (3, n) float array
        ``(L_psi - L) X``, from the same pass; only when ``X`` is given.
    """
    L = as_csr(L)
    data = np.empty(L.nnz)
    n = L.shape[0]
    DX = np.empty((3, n))
    drift_weights(L.indptr, L.indices, np.ascontiguousarray(L.data, dtype=np.float64),
                  np.ascontiguousarray(psi, dtype=np.float64), float(peclet),
                  np.zeros((3, n)) if X is None else np.ascontiguousarray(X, dtype=np.float64),
                  data, DX)
    L_psi = sp.csr_matrix((data, L.indices, L.indptr), shape=L.shape)
    return L_psi if X is None else (L_psi, DX)


def surface_components(faces, n_vertices):
    """Number of connected components of the triangle mesh ``faces`` (m, 3): the
    potential (R2) is pinned once and its source balances the whole surface's
    area, so the redistribution is written for a connected surface."""
    from scipy.sparse.csgraph import connected_components

    f = np.asarray(faces)
    rows, cols = f[:, [0, 1, 2]].ravel(), f[:, [1, 2, 0]].ravel()
    graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n_vertices, n_vertices))
    return connected_components(graph, directed=False)[0]

