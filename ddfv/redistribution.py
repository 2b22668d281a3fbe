"""Area-oriented tangential redistribution of the diamond mesh (journal version).

The flow (1.1) is changed only by a tangential velocity ``v_T``, which
moves points along the surface and leaves its shape alone::

    d_t phi = h + v_T,      v_T = grad_G psi                                   (R1)

(Tomek & Mikula, ESAIM: M2AN 53(6) (2019) 1797-1840, after Mikula,
Remesikova, Sarkoci & Sevcovic, SIAM J. Sci. Comput. 36(4) (2014)
A1384-A1414; their full texts were not available here: (R1)-(R5) are
derived below and in ``ddfv/README.md``, section "Journal version").

Derivation. With ``g`` the local area element and ``V = (d_t phi . N) N``
the normal velocity, ``d_t ln g = div_G (d_t phi) = div_G v_T - h . V``
(on a sphere of radius ``R(t)``: ``2 R'/R`` on both sides). The total area
``A`` obeys ``d_t ln A = -<h . V>`` (``<.>`` the surface mean). Asking
the relative density ``q = g N / A`` (``N`` the number of covolumes) to
relax to 1 at rate ``omega``, ``d_t q = omega (1 - q)`` in ``ln`` form
``d_t ln q = omega (1/q - 1)``, gives the surface Poisson problem::

    Delta_G psi = h . V - <h . V> + omega (A / (N m_i) - 1)                   (R2)

per covolume ``i`` of area ``m_i`` (the local area density is the
covolume area). Integrated over covolume ``i`` with the scheme's own
fluxes, ``-(K psi)_i ~ int_{V_i} Delta_G psi`` (2.9)::

    K psi = -s,   s_i = m_i (h.V_i - <h.V>) + omega (A / N - m_i)             (R3)

``K`` is the DDFV stiffness matrix of :mod:`ddfv.assembly`; its F-rows and
its T-rows each sum to zero (every flux leaves one covolume of its family
and enters another), so ``K psi = -s`` is solvable iff ``s`` sums to zero
over the F-covolumes and over the T-covolumes (the means ``<h.V>`` and
``A / N`` are taken per family), and ``psi`` is determined up to a
two-dimensional kernel (on a closed surface one constant on the
F-vertices and one on the T-vertices, which no diamond gradient sees),
fixed in :class:`TangentialPotential`.

On a fixed (Dirichlet) boundary no point may cross the boundary:
``grad psi . nu = 0`` (Neumann), which is the scheme's covolume balance
without the flux through the boundary edge (the T-row of a boundary
diamond loses the reflected ghost of Section 2.2.5; the F-rows of a
boundary diamond take the flux through its dual curve ``T_t1 -> S`` only,
with the ghost, :func:`neumann_stiffness`), and the boundary F-vertices
neither move nor are driven (their target area is their own area,
``h.V = 0``).

The velocity. The gradient of ``psi`` on diamond ``d`` is the tangent
vector ``g_d = a u + b v`` in the plane of the diagonals with
``g_d . u = psi_b - psi_a`` and ``g_d . v = psi_t2 - psi_t1`` (exact for an
affine ``psi`` on a planar diamond; (2.7))::

    [u.u  u.v] [a]   [psi_b - psi_a  ]
    [u.v  v.v] [b] = [psi_t2 - psi_t1]                                         (R4)

At a vertex, ``v_T`` is the mean of ``g_d`` over its diamonds weighted by
their areas ``J_d / 2``, projected onto the tangent plane of the vertex
normal ``N`` of :func:`ddfv.geometry.vertex_normals`::

    v_T(i) = (I - N N^T) sum_d J_d g_d / sum_d J_d                            (R5)

How it enters the step: semi-implicitly, as an advection. A tangential
velocity ``grad psi`` of the parametrisation is, in the equation of the
positions, ``grad psi . grad_G X`` (``grad_G X . w = w`` for a tangent
``w``), and::

    X_t = Delta_G X + grad psi . grad_G X = e^{-psi} div_G (e^psi grad_G X)   (R6)

a weighted Laplace-Beltrami: the flux of ``e^psi grad X`` through a dual
curve, divided by ``e^psi`` of the balance's own vertex. Per inner diamond,
the flux ``flux_a`` of the F-row of ``a`` ((2.12)) is multiplied by the
Scharfetter-Gummel weight of its edge (``psi`` at the old state (R3), ``X``
at the new level)::

    flux_a -> B(psi_a - psi_b) flux_a,   flux_b -> B(psi_b - psi_a) flux_b,
    B(x) = x / (e^x - 1)                                                      (R7)

(:func:`drift_system`): ``e^{-psi_a}`` times the logarithmic mean of
``e^psi`` on the edge, exact for ``psi`` linear along it (the flux ``e^psi
X'`` is constant), ``1 + (psi_b - psi_a)/2 + ...``: to first order the
Laplacian plus the centred advection ``(psi_b - psi_a) flux_a / 2``, for
large differences the upwind one. The T-rows keep the scheme's fluxes: the
variant that redistributes (``chord-redistribute-carried``) carries its
T-vertices with their triangles anyway, and a weight on the T-rows from the
F-values (the T-values of ``psi`` carry their own constant) made the
weights exponential in the differences (``e^{psi_d - psi_t}``): the first
version of (R7), one weight ``e^psi`` per diamond (symmetric), blew up the
public mesh blub (area x 1.5e6 in one step). The normal part of the drift
at the old state is added back explicitly, ``g = N N . (A_psi - A) X^n / tau``
(``A_psi``, ``A`` the row-scaled systems with and without (R7)), as (3.6)
removes a tangential part: the normal motion stays the scheme's.

The edge Peclet number is limited, ``psi_b - psi_a`` clipped to
``[-P, P]`` in (R7) (``peclet``, default :data:`PECLET` = 0.1)::

    B(psi_a - psi_b) -> B(max(min(psi_a - psi_b, P), -P))                     (R8)

On the public real meshes ``psi`` differs by up to 23 across an edge (the
``h.V`` term at small features): unlimited, a step moves points by ``~0.1
|psi_b - psi_a|`` edge lengths and folds triangles within 1-2 steps; the
limit is inactive on a smooth refinement series once ``h |grad psi| < P``.
Stability: the weights are positive and within ``[B(P), B(-P)] = [0.95,
1.05]``, so the drift is a relative change of each F-row's fluxes by at most
5 %; no step restriction comes with it (the matrix stays the implicit
scheme's up to that change). Unlike the scheme's chord matrix, the matrix
is not a row scaling of a symmetric one (the two rows of an edge are
weighted differently).

The vertex velocity ``v_T`` of (R4)-(R5) (:func:`vertex_gradients`) is the
velocity (R6) carries, kept for diagnostics and tests.

T-vertices carried by their triangles (:func:`carry_t_vertices`): a
T-vertex keeps the barycentric coordinates ``lambda^0`` of its initial
projection in its triangle and its height above the triangle's plane
from the scheme; this is a tangential velocity of the T-vertices alone,
applied at the end of the step (see ``ddfv/README.md``).
"""

from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp

from kept_factor import KeptFactorSolver, as_csr, factorise, family_blocks, pinned

from .assembly import flux_coefficients

#: default relaxation rate ``omega`` of (R2), in 1 / time
OMEGA = 1.0
#: default limit of the edge Peclet number ``|psi_b - psi_a|`` of (R8)
PECLET = 0.1
#: relative residual of the potential's solve (:class:`TangentialPotential`)
POTENTIAL_RTOL = 1e-4
#: most Gauss-Seidel sweeps over the T-rows of the potential's extrapolated start
#: (:class:`TangentialPotential`)
T_SWEEPS = 3
#: a sweep whose rows' squared residual (taken before each update) is at most this times
#: the squared tolerance ``(rtol |b|)^2`` is the last (4: the residual twice the tolerance)
T_FRACTION = 4.0


def neumann_stiffness(assembler, geom):
    """The DDFV stiffness ``K`` with the Neumann condition of (R3) on a boundary.

    Parameters
    ----------
    assembler : ddfv.assembly.Assembler
    geom : DiamondGeometry

    Returns
    -------
    (n, n) scipy.sparse.csr_matrix
        ``-(K psi)_i`` approximates ``int_{V_i} Delta_G psi`` (2.9) with no
        flux through the boundary: the rows of boundary F-vertices are the
        flux balance of their (cut) covolume through the dual curve
        ``T_t1 -> S`` of each boundary diamond (the missing T-vertex is the
        reflection ``F_a + F_b - T_t1``, Section 2.2.5, as in the geometry;
        the curve is half of the reflected diamond's), and a boundary diamond adds nothing to
        the row of its T-vertex. Rows of each family sum to zero; constants
        on each family and affine functions on a planar mesh (chord
        ``|gamma|``) are in the kernel.
    """
    from . import kernels as k

    mesh = assembler._mesh
    K = assembler._matrix(geom, np.ones(mesh.n_unknowns), 0.0)
    if not mesh.has_boundary:
        return K
    bnd = np.flatnonzero(mesh.boundary)
    alpha, beta, alpha_hat, beta_hat = flux_coefficients(SimpleNamespace(**{
        name: np.asarray(getattr(geom, name))[bnd]
        for name in ("gamma_t", "gamma_f", "J", "len_u", "len_v", "uv")}))
    # F-rows: the assembly leaves out the ghost T_t2 = F_a + F_b - T_t1 of Section
    # 2.2.5 (its F-rows are Dirichlet rows) and its geometry measures the dual
    # curve T_t1 -> S -> ghost; on the surface the curve ends at S, the edge
    # midpoint: half of it. The flux balance needs
    # flux_a = (alpha (psi_b - psi_a) - beta (psi_a + psi_b - 2 psi_t1)) / 2 = -flux_b.
    # T-row: the ghost's flux through the boundary edge is taken out (Neumann).
    # Every entry is in the assembler's pattern (a boundary diamond has its slots
    # (a, a), (a, b), (b, a), (b, b), (t1, a), (t1, b), (t1, t1)): added into K's data.
    slots = assembler._slots[bnd][:, [k.SLOT_AA, k.SLOT_AB, k.SLOT_BA, k.SLOT_BB,
                                      k.SLOT_T1_A, k.SLOT_T1_B, k.SLOT_T1_T1]]
    vals = np.stack([(beta - alpha) / 2, (alpha + beta) / 2,
                     (alpha - beta) / 2, -(alpha + beta) / 2,
                     beta_hat + alpha_hat, alpha_hat - beta_hat, -2.0 * alpha_hat], axis=1)
    K.data += np.bincount(slots.ravel(), vals.ravel(), minlength=K.nnz)
    return K


def potential_operators(assembler, geom, A, chi, dt, X, N):
    """``h . V`` of (R3) at every vertex and the stiffness ``K`` of (R3), from the
    step's matrix ``A = I + dt diag(1/chi) K`` at the state ``X``.

    ``h . V = (h . N)^2`` with ``h = (X - A X) / dt`` (``V = (h . N) N``, mean
    curvature flow), the scheme's discrete Laplacian of ``X`` as in (3.6). On a
    closed surface ``K`` is the scheme's stiffness itself, read off ``A`` in the
    same compiled pass over its rows
    (:func:`ddfv.tangential_kernels.squared_normal_speed_kernel`): ``K_ij = (chi_i /
    dt) A_ij`` off the diagonal and ``K_ii`` minus the sum of the row's others (the
    rows of ``K`` sum to zero), instead of a second assembly (level 5 of the sphere:
    0.6 ms of a 12 ms step); it equals the assembled ``K`` to rounding. With a
    boundary (Dirichlet rows in ``A``, Neumann condition in (R3)):
    :func:`neumann_stiffness`.

    Parameters
    ----------
    assembler : ddfv.assembly.Assembler
        The assembler of ``A``.
    geom : DiamondGeometry
        The geometry of ``X``.
    A : (n, n) scipy.sparse.csr_matrix
        :meth:`ddfv.assembly.Assembler.system` at ``X`` with step ``dt``.
    chi : (n,) float array
        Covolume areas of ``X``, F-vertices first.
    dt : float
    X, N : (3, n) float arrays
        The state (own numbering) and its unit vertex normals
        (:func:`ddfv.geometry.vertex_normals`).

    Returns
    -------
    hV : (n,) float array
    K : (n, n) scipy.sparse.csr_matrix
        In the pattern of ``A``.
    """
    from .tangential_kernels import squared_normal_speed_kernel

    closed = not assembler._mesh.has_boundary
    hV, K_data = np.empty(A.shape[0]), np.empty(A.nnz if closed else 0)
    squared_normal_speed_kernel(A.indptr, A.indices, A.data, assembler._diag,
                                np.asarray(X, dtype=np.float64), N, float(dt),
                                np.asarray(chi, dtype=np.float64), hV, K_data)
    return hV, assembler.in_pattern(K_data) if closed else neumann_stiffness(assembler, geom)


def redistribution_source(chi, hV, n_f, fixed=None, omega=OMEGA):
    """The source ``s`` of (R3), per covolume: ``K psi = -s``.

    Parameters
    ----------
    chi : (n_f + n_t,) float array
        Covolume areas ``m_i``, F-vertices first.
    hV : (n_f + n_t,) float array
        ``h . V`` at every vertex (``H^2`` for mean curvature flow).
    n_f : int
    fixed : (n_f,) bool array, optional
        Dirichlet F-vertices: no motion, no drive (``h.V = 0``, target area
        their own).
    omega : float
        Relaxation rate of (R2) (1 / time).

    Returns
    -------
    (n_f + n_t,) float array
        ``s_i = m_i (h.V_i - <h.V>) + omega (A/N - m_i)``, the means taken
        over each family (F, T) separately; sums to zero over each family.
    """
    chi = np.asarray(chi, dtype=float)
    hV = np.array(hV, dtype=float)
    target = np.empty_like(chi)
    driven = np.ones(len(chi), dtype=bool)
    if fixed is not None:
        driven[:n_f] = ~np.asarray(fixed, dtype=bool)
        hV[:n_f][~driven[:n_f]] = 0.0
    for family in (slice(0, n_f), slice(n_f, len(chi))):
        m, d = chi[family], driven[family]
        area = m.sum()
        mean_hV = np.dot(m, hV[family]) / area                         # <h.V>  (R2)
        if d.all():                         # a closed surface: the same sums, no copies
            target[family] = area / max(len(m), 1)                     # A / N  (R2)
        else:
            target[family] = np.where(d, m[d].sum() / max(d.sum(), 1), m)
        hV[family] -= mean_hV
    return chi * hV + omega * (target - chi)


class TangentialPotential(KeptFactorSolver):
    """Solver of (R3) along a flow: ``K psi = -s``, its two free constants fixed.

    The F-rows and the T-rows of ``K`` each sum to zero, so ``K`` has a
    two-dimensional kernel: on a closed surface a constant on the F-vertices
    and another on the T-vertices (no diamond gradient sees them); on a
    surface with boundary the reflected ghost of the boundary diamonds couples
    the two families and the second kernel vector has a gradient near the
    boundary. ``psi`` is fixed by ``psi = 0`` at F-vertex 0 (the gradients
    do not see the constant) and by
    ``sum_t chi_t (psi_t - mean of psi over the corners of t) = 0``: the
    T-values are on average those of their triangles.

    F-vertex 0 and T-vertex 0 are pinned: ``A = P K P + I - P`` (``P``
    zeroes those two entries; :func:`kept_factor.pinned`), symmetric positive
    definite where ``K`` is symmetric (the chord ``|gamma|`` on a closed
    surface), and ``A x = b`` with ``b = 0`` at the pinned entries. The
    systems of a flow, whose geometry moves by ``O(tau)`` a step, are solved
    with a kept factorisation (:class:`kept_factor.KeptFactorSolver`: sparse
    Cholesky and conjugate gradients where ``A`` is symmetric positive
    definite, else sparse LU and iterative refinement, from the linear
    extrapolation ``2 x^{n-1} - x^{n-2}`` of the last two solutions, until
    ``|b - A x| <= rtol |b|``, factorised again when that takes more than
    ``max_iterations``). Measured at level 5 of the sphere (30 722 unknowns,
    ``benchmarks/bench_potential.py``): the Cholesky solve is 0.55 x the
    LU's. One solve for a particular solution and, on a surface with
    boundary, one for the kernel vector ``w`` (``w_F0 = 0``, ``w_T0 = 1``:
    ``w = e_T0 + y``, ``A y = -P K e_T0``; on a closed surface ``w`` is 1 on
    the T-vertices, 0 on the F-vertices). ``psi`` only sets a tangential
    velocity (any leaves the shape alone), so its tolerance is
    :data:`POTENTIAL_RTOL` = 1e-4 (it was 1e-7): the extrapolated start meets
    it in most steps with no iteration (level 5 of the sphere: 0.42 CG
    iterations per step against 1.02), and the Table 3.1 setting's errors
    (levels 1-5) are unchanged to 7 digits, their orders, the smallest angle
    and the largest aspect ratio to the 4th decimal (``ddfv/README.md``, item
    22 of its deviations).

    The kept factorisation is that of the two diagonal blocks, F-F and T-T
    (:func:`kept_factor.family_blocks`), where ``A`` is symmetric: the F-T coupling
    of the diamonds makes the whole matrix's Cholesky factor several times denser
    than the blocks' (level 5 of the sphere, 30 722 unknowns, a sequence of 100
    steps' systems at rtol 1e-4, CPU: the whole matrix's factor 323 ms and 6.1 ms
    a solve at 0.91 CG iterations, the blocks' 166 ms and 3.9 ms at 1.02
    iterations); the blocks are symmetric positive definite where ``A`` is, so CG
    converges to the same solution, to the same tolerance.

    The extrapolated start is smoothed on the T-rows before CG (``smooth`` of
    :meth:`kept_factor.KeptFactorSolver.solve`): Gauss-Seidel sweeps over the T-rows,
    the F-values fixed (:func:`ddfv.tangential_kernels.pinned_gauss_seidel_kernel`),
    at most :data:`T_SWEEPS`, until a sweep finds its rows' residual within twice the
    tolerance (:data:`T_FRACTION`). The start's residual is in the T-rows: at level 5
    of the sphere (``ddfv-chord-redistribute-carried``, the extrapolation of two exact
    solutions) 1.0-3.0e-4 of ``|b|`` there against 1-2e-5 in the F-rows, the start
    itself within 2e-6 of the solution. The source (R3) at the T-vertices moves
    roughly from one step to the next: its second difference in time, which the linear
    extrapolation misses, is 2-5e-4 of its norm there against 2-3e-5 at the
    F-vertices (steps 100-104); a sweep over the T-rows (a T-vertex's row: its three
    T-neighbours and three F-corners) divides that residual by about 4 (at level 6
    too). Each sweep costs about
    half a product with ``K``; a CG iteration costs a product and the two blocks'
    factor solves (level 5: 0.17 and 1.8 ms). Measured on the systems of 200 steps at
    level 5 and 60 at level 6, CG iterations a step (after the first 40 and 15): level 5
    0.86 without sweeps, 0.39 with one, 0.42 with up to three; level 6 1.00, 0.84,
    0.44. CG checks the smoothed start's residual as any start's: the solution is
    within the tolerance whatever the sweeps do (40 steps of a bumped level-3 sphere:
    the vertices within 6e-7 edge lengths of the flow with a direct solve, as
    without the sweeps).

    Parameters
    ----------
    mesh : DiamondMesh
    rtol : float
        Relative residual of each solve (default :data:`POTENTIAL_RTOL`).
    max_iterations : int
    blocks : bool
        Factorise the two families' diagonal blocks (default) rather than ``A``
        (a direct solve on a fresh factor: :func:`tangential_potential`).
    """

    def __init__(self, mesh, rtol=None, max_iterations=4, blocks=True):
        super().__init__(POTENTIAL_RTOL if rtol is None else rtol, max_iterations,
                         factorise=family_blocks(mesh.n_f) if blocks else factorise)
        self.mesh = mesh
        self._keep = np.ones(mesh.n_unknowns)
        self._keep[[0, mesh.n_f]] = 0.0

    def __call__(self, K, source, chi):
        """``psi`` with ``K psi = -source`` (:func:`neumann_stiffness`,
        :func:`redistribution_source`; ``source`` sums to zero over each
        family), ``chi`` the (n,) covolume areas.

        Returns
        -------
        (n,) float array
        """
        from .tangential_kernels import pinned_gauss_seidel_kernel

        n_f, faces, keep = self.mesh.n_f, self.mesh.faces, self._keep
        K = as_csr(K)
        system = pinned(K, keep)
        pattern = (K.indptr.astype(np.int32, copy=False),
                   K.indices.astype(np.int32, copy=False),
                   np.ascontiguousarray(K.data, dtype=np.float64))

        def smooth(x, b):        # the start's T-rows: Gauss-Seidel sweeps (see above)
            tol = T_FRACTION * (self.rtol * np.linalg.norm(b)) ** 2
            for _ in range(T_SWEEPS):
                if pinned_gauss_seidel_kernel(*pattern, keep, b, x, n_f, len(x)) <= tol:
                    break
        psi = self.solve(-np.asarray(source, dtype=float) * keep, *system, sequence="psi",
                         smooth=smooth)

        def offset(x):      # sum_t chi_t (x_t - mean of x over the corners of t)
            corners = x[faces[:, 0]] + x[faces[:, 1]] + x[faces[:, 2]]
            return np.dot(chi[n_f:], x[n_f:] - corners / 3.0)

        if not self.mesh.has_boundary:      # w: 1 on the T-vertices, offset(w) = sum chi_t
            return np.r_[psi[:n_f], psi[n_f:] - offset(psi) / chi[n_f:].sum()]
        e = np.zeros(len(keep))
        e[n_f] = 1.0
        w = e + self.solve(-keep * (K @ e), *system, sequence="w")
        return psi - offset(psi) / offset(w) * w


def tangential_potential(K, source, mesh, chi):
    """``psi`` of (R3) in one call (see :class:`TangentialPotential`), by the Cholesky
    factorisation of the whole matrix (or its LU): a direct solve.

    Parameters
    ----------
    K : (n, n) sparse matrix
        :func:`neumann_stiffness`.
    source : (n,) float array
        :func:`redistribution_source`.
    mesh : DiamondMesh
    chi : (n,) float array
        Covolume areas.

    Returns
    -------
    (n,) float array
    """
    return TangentialPotential(mesh, blocks=False)(K, source, chi)


def diamond_gradients(mesh, geom, psi):
    """(3, n_d) the gradient ``g_d`` of ``psi`` on every diamond (R4).

    Parameters
    ----------
    mesh : DiamondMesh
    geom : DiamondGeometry
        With the vectors ``u``, ``v``.
    psi : (n_f + n_t,) float array

    Returns
    -------
    (3, n_d) float array
        ``g_d = a u + b v`` with ``g_d . u = psi_b - psi_a``,
        ``g_d . v = psi_t2 - psi_t1`` (on a boundary diamond the missing
        ``psi_t2`` is the reflection ``psi_a + psi_b - psi_t1``, as the
        T-vertex, Section 2.2.5).
    """
    a, b, t1, t2 = mesh.diamonds.T
    pf, pt = psi[:mesh.n_f], psi[mesh.n_f:]
    du = pf[b] - pf[a]
    p2 = np.where(t2 >= 0, pt[np.maximum(t2, 0)], pf[a] + pf[b] - pt[t1])
    dv = p2 - pt[t1]
    uu = np.einsum("ij,ij->j", geom.u, geom.u)
    vv = np.einsum("ij,ij->j", geom.v, geom.v)
    det = uu * vv - geom.uv ** 2                       # J^2 (2.8)
    ca = (vv * du - geom.uv * dv) / det
    cb = (uu * dv - geom.uv * du) / det
    return ca * geom.u + cb * geom.v


def vertex_gradients(mesh, geom, psi, normals):
    """(3, n_f + n_t) the tangential velocity ``v_T = grad psi`` at every vertex (R5).

    Parameters
    ----------
    mesh : DiamondMesh
    geom : DiamondGeometry
        With the vectors ``u``, ``v``.
    psi : (n_f + n_t,) float array
    normals : (3, n_f + n_t) float array
        Unit vertex normals (:func:`ddfv.geometry.vertex_normals`).

    Returns
    -------
    (3, n_f + n_t) float array
        The ``J``-weighted mean of the diamond gradients of the vertex's
        diamonds, projected onto its tangent plane.
    """
    n, n_f = mesh.n_unknowns, mesh.n_f
    a, b, t1, t2 = mesh.diamonds.T
    inner = t2 >= 0
    corners = np.concatenate([a, b, n_f + t1, n_f + t2[inner]])
    g = diamond_gradients(mesh, geom, psi) * geom.J
    weights = np.concatenate([geom.J, geom.J, geom.J, geom.J[inner]])
    total = np.bincount(corners, weights, minlength=n)
    mean = np.stack([np.bincount(corners, np.concatenate([gk, gk, gk, gk[inner]]),
                                 minlength=n) for gk in g]) / total
    return mean - (mean * normals).sum(axis=0) * normals


def drift_system(assembler, A, geom, chi, dt, psi, peclet=np.inf, X=None):
    """The matrix of (R7) in row-scaled form: ``A + dt diag(1/chi) D``.

    Parameters
    ----------
    assembler : ddfv.assembly.Assembler
        The assembler of ``A``: ``D`` is added into its pattern.
    A : (n, n) scipy.sparse.csr_matrix
        The scheme's system ``I + dt diag(1/chi) K`` at the same state
        (:meth:`ddfv.assembly.Assembler.system`).
    geom : DiamondGeometry
    chi : (n,) float array
        Covolume areas, F-vertices first.
    dt : float
    psi : (n,) float array
        The potential (R3); only its F-values enter.
    peclet : float
        Largest ``|psi_b - psi_a|`` a weight sees: the differences are clipped
        to ``[-peclet, peclet]`` (R8).
    X : (3, n) float array, optional
        Positions (own numbering) whose drift ``dt diag(1/chi) D X`` is wanted too.

    Returns
    -------
    A_psi : (n, n) scipy.sparse.csr_matrix
        In the pattern of ``A`` (same ``indices`` and ``indptr``). ``D``
        multiplies the F-row part of each inner diamond's fluxes by ``w - 1``,
        ``w_a = B(psi_a - psi_b)`` in the row of ``a`` and ``w_b = B(psi_b -
        psi_a)`` in the row of ``b``, ``B(x) = x / (e^x - 1)``, ``B(0) = 1``
        (the compiled ``ddfv.kernels._bernoulli``); T-rows, boundary diamonds
        and Dirichlet rows are those of ``A``. With ``psi`` constant, ``A``
        itself.
    drift : (3, n) float array
        ``(A_psi - A) X``, from the same compiled pass; only when ``X`` is given.
    """
    from .geometry import _diamond_indices
    from .kernels import drift_kernel

    mesh = assembler._mesh
    if A.shape != assembler.shape or A.nnz != assembler.nnz:
        raise ValueError(f"A ({A.shape}, {A.nnz} nonzeros) is not in the pattern of the "
                         f"assembler ({assembler.shape}, {assembler.nnz} nonzeros)")
    scale = np.zeros(mesh.n_unknowns)
    free = ~mesh.boundary_vertices
    scale[:mesh.n_f][free] = dt / np.asarray(chi, dtype=np.float64)[:mesh.n_f][free]
    factors = (np.asarray(getattr(geom, name), dtype=np.float64)
               for name in ("gamma_t", "gamma_f", "J", "len_u", "len_v", "uv"))
    data = A.data.copy()
    n = mesh.n_unknowns
    DX = np.empty((3, n))
    drift_kernel(assembler._inner, *factors, assembler._slots, _diamond_indices(mesh),
                 np.ascontiguousarray(psi, dtype=np.float64), scale, float(peclet),
                 np.zeros((3, n)) if X is None else np.ascontiguousarray(X, dtype=np.float64),
                 mesh.n_f, data, DX)
    A_psi = assembler.in_pattern(data)
    return A_psi if X is None else (A_psi, DX)


def carry_t_vertices(F, T, faces, lam):
    """T-vertices moved tangentially to the barycentric coordinates ``lam`` of their triangle.

    Parameters
    ----------
    F : (n_f, 3) float array
    T : (n_t, 3) float array
    faces : (n_t, 3) int array
    lam : (n_t, 3) float array
        Barycentric coordinates (rows sum to 1) to keep.

    Returns
    -------
    (n_t, 3) float array
        ``Q + ((T - Q) . n) n`` with ``Q = sum_k lam_k F_k`` and ``n`` the
        unit normal of the triangle: the height of ``T`` above the plane of
        its triangle is kept, its projection is put at ``Q`` (one compiled pass,
        :func:`ddfv.tangential_kernels.t_vertices_kernel`: catenoid level 3, 6 144
        triangles, 0.61 ms in numpy, 0.10 ms compiled).
    """
    from .tangential_kernels import moved_t_vertices

    return moved_t_vertices(F, T, faces, lam, carry=True)


def surface_components(faces, n_vertices):
    """Number of connected components of the triangle mesh ``faces`` (m, 3).

    The redistribution's potential is defined up to one constant per family
    and component, and its source balances the area of the whole surface;
    both are written for a connected surface (:class:`ddfv.Flow` refuses
    others with ``tangential="redistribute"``).
    """
    from scipy.sparse.csgraph import connected_components

    f = np.asarray(faces)
    rows, cols = f[:, [0, 1, 2]].ravel(), f[:, [1, 2, 0]].ravel()
    graph = sp.coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n_vertices, n_vertices))
    return connected_components(graph, directed=False)[0]

