"""The evolving finite element algorithm of Kovacs, Li and Lubich (KLL) for mean curvature flow.

B. Kovacs, B. Li, Ch. Lubich, "A convergent evolving finite element algorithm for
mean curvature flow of closed surfaces", Numer. Math. 143 (2019) 797-853 (arXiv
1805.06667). Besides the position ``X`` it evolves the outer unit normal ``nu``
and the mean curvature ``H`` by Huisken's evolution equations, and moves the
surface with the velocity ``v = -H nu`` built from them::

    d/dt X = v = -H nu                                                     (KL1)
    d nu = Delta_G nu + |A|^2 nu,    d H = Delta_G H + |A|^2 H,    |A|^2 = |grad_G nu|^2   (KL2)

(``d`` the material derivative, ``Delta_G`` the Laplace-Beltrami operator of the
surface ``G``: Huisken's evolution equations, as the paper's abstract names them;
its full text was not available to us, ``baselines/README.md``). Sign:
``H = div_G nu``, a sphere of radius ``R`` with its outer normal has ``H = 2 / R``
and shrinks as ``r(t) = sqrt(R^2 - 4 t)``; the product ``H nu`` (the mean
curvature vector, ``-Delta_G X``) does not depend on which side ``nu`` points to.

Discretisation (derived here; our labels (KL1)-(KL6), ``baselines/README.md``)
-------------------------------------------------------------------------
Evolving P1 elements on the surface of the nodes ``X`` (degree 1: the paper's
proof needs degree >= 2, ``baselines/README.md``), ``u = (nu, H)`` nodal P1 values.
The weak form of (KL2) is ``M(X) du/dt + L(X) u = f(X, u)`` with ``M`` the mass,
``L`` the stiffness and ``f_i = int |grad_G nu|^2 u phi_i`` (the paper's
matrix-vector form). The harness's integrators (``mcfbench.running.integrators``,
(I1)) give the paper's linearly implicit BDF (its (4.2) as cited there): operators and the
nonlinearity at the extrapolated state ``X*, u*``, ``B`` the base, ``dt`` the
scaled step. Lumped mass ``m_i`` (barycentric), cotangent stiffness ``L``, both
of ``X*``, row-scaled as the cotangent scheme's (C3)::

    (I + dt diag(1/m) L) u = B_u + dt (w / m) u*                            (KL3)
    w_i = sum_{t ni i} |t| |A|_t^2 / 3,   |A|_t^2 = |E_t|_F^2 / |N_t|^2          (KL4)
    E_t = sum_k nu*_k (x) e_k

``N_t`` the area vector of triangle ``t`` of ``X*`` (``|N_t| = 2 |t|``), ``e_k``
its edge opposite corner ``k``: on a flat triangle ``grad phi_k = N_t x e_k /
|N_t|^2``, so ``grad_t nu*_c = N_t x E_c / |N_t|^2`` and ``|grad_t nu*|^2 =
|E_t|^2 / |N_t|^2`` (``E_t`` lies in the triangle's plane). ``w`` is the
lumped quadrature of ``f``: one value of ``|A|^2`` per triangle.

The velocity law (KL1) with the BDF derivative of ``X``, ``dX/dt = v^n`` with
``v^n = -H^n nu^n`` (our reading of the abstract's velocity law "projected to the
finite element space": the nodal interpolation, both factors at the new level), is
bilinear in the new ``(nu, H)``; it is linearised at the extrapolation::

    X + dt (H* nu + H nu*) = B_X + dt H* nu*                                 (KL5)

which differs from ``X = B_X - dt H nu`` by ``dt (H - H*) (nu - nu*)``,
``O(tau^(2k+1))`` per step for BDF-k (``O(tau^3)`` for Euler): below the local
error of every integrator, and the step stays ONE linear system that the
harness solves and extrapolates like any other (the BDF3 start-up combines whole
solutions). (KL3) and (KL5) together, the state ``U = (X, nu, H)`` (7, n)::

    [ I   dt H*  dt nu* ] [X ]   [B_X + dt H* nu*     ]
    [ 0   S      0      ] [nu] = [B_nu + dt w/m nu*   ]                     (KL6)
    [ 0   0      S      ] [H ]   [B_H + dt w/m H*     ]

``S = I + dt diag(1/m) L`` (C3), ``dt H*`` and ``dt nu*`` diagonal: a (7n, 7n)
block upper triangular matrix, not symmetric; its eigenvalues are 1 and those
of ``S``. Its lower right block is ``I_4 (x) S`` (``nu_1, nu_2, nu_3, H``
decoupled, one matrix) and its leading block the identity, so the step is
solved by blocks (:class:`BlockSystem`, which the harness's solver reduces):
``S [nu_1 nu_2 nu_3 H] = [b_nu b_H]`` (one factorisation, or one block
BiCGStab iteration, for four right-hand sides), then::

    X_c = b_X,c - dt H* nu_c - dt nu*_c H                                    (KL7)

Initial values (any mesh): ``nu^0`` the unit area-weighted vertex normals
(:func:`baselines.mdr.unit_vertex_normals`), ``H^0_i = nu^0_i . (L X^0)_i / m_i`` the
normal part of the cotangent mean curvature vector (``-Delta X = H nu``), as
MDR's ``H``.

Open surfaces (the paper's are closed; ours, ``baselines/README.md``, kll item 5):
the boundary curve is held fixed as in the other schemes, and every block of
(KL6) gets Dirichlet rows at the boundary vertices (``S``'s rows of the
identity, the coupling ``dt H*``, ``dt nu*`` and the source zero there)::

    X = B_X,    nu = n_b(X*),    H = 0        at a boundary vertex         (KL8)

``H = 0`` because the boundary does not move: ``v = -H nu = 0`` there for
``t > 0`` (at ``t = 0`` too, replacing the cotangent value, which a boundary
vertex's half one-ring does not define); ``n_b(X*)`` is the normal of the
extrapolated discrete surface at the vertex, from a quadric fitted to its
two-ring (:func:`boundary_normals`, O(h^2); the one-sided vertex normal is
O(h) off and costs ``nu`` an order on the catenoid). Both come from the
discrete surface, not from a problem's exact solution; a closed mesh is
stepped as before, bit for bit.
"""

from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from .vertex_flow import VertexFlow
from .tangential_kernels import gradient_norm_weights
from .mdr import unit_vertex_normals

ROWS = 7
"""The state ``(X, nu, H)``: 3 + 3 + 1 rows."""

SPREAD = 4.0
"""``max_i S_ii`` above which the flow keeps an incomplete LU of ``S`` for the solver
(:func:`incomplete_lu`). ``S = I + dt diag(1/m) L`` has its eigenvalues in ``[1, 2
max_i S_ii - 1]`` (Gershgorin; cotangent weights positive), so plain BiCGStab's
iterations follow ``max_i S_ii``: 1.6 on every icosphere level and 1.9 on the catenoid
(left as they were: 1-5 iterations a step), but 23, 40, 71 on bob refined by Loop to
64 000, 256 000 and 1 024 000 vertices (``benchmarks/README.md``, "KLL's step"), where
the one-rings of the base mesh's valence-4 vertices shrink by Loop's subdominant
eigenvalue 3/8 a level instead of 1/2, their ``dt / h^2`` growing by (1/2 / 3/8)^2 =
1.78 a level, and BiCGStab's iterations with it (21-22, 27, 30-37 at a run's steps 2-4)."""

ILU = {"drop_tol": 1e-3, "fill_factor": 1.5}
"""``scipy.sparse.linalg.spilu``'s settings of :func:`incomplete_lu`: 2-4 BiCGStab
iterations a step on bob's three levels (``benchmarks/README.md``, "KLL's step"); drop
tolerances 1e-2 and 1e-1 (fill 1) take 6-8."""

DRIFT = 1.0
"""The kept factor is made anew when a diagonal entry of ``S`` has moved from the
factor's by more than this times the factor's (``|S_ii - P_ii| > DRIFT P_ii``), and for
another shape. On bob's level 4 the factor of the first step still takes BiCGStab to
2-3 iterations 100 steps and a drift of 1 later, 3-4 at a drift of 3.8."""


def curvature_weights(vertices, faces, nu):
    """``w`` of (KL4): the lumped ``int |grad_G nu|^2 phi_i``, one value per triangle
    (kernel :func:`baselines.tangential_kernels.gradient_norm_weights`).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    nu : (n, 3) float array
        Nodal values of a P1 vector field.

    Returns
    -------
    w : (n,) float array
        ``sum_{t ni i} |t| |grad_t nu|^2 / 3``; triangles of zero area add nothing.
    squared : (m,) float array
        ``|grad_t nu|^2`` (0 on a triangle of zero area).

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> w, sq = curvature_weights(V, np.array([[0, 1, 2]]), V * [2.0, 3.0, 0.0])
    >>> sq.round(12).tolist(), w.round(4).tolist()          # grad (2x, 3y): 4 + 9
    ([13.0], [2.1667, 2.1667, 2.1667])
    """
    w, squared = np.empty(len(vertices)), np.empty(len(faces))
    # any strides: the flow's (n, 3) views of its (3, n) state are not copied
    gradient_norm_weights(np.asarray(vertices, dtype=np.float64),
                          np.asarray(faces, dtype=np.int64),
                          np.asarray(nu, dtype=np.float64), w, squared)
    return w, squared


def two_rings(edges, n, vertices):
    """The vertices within two edges of each of ``vertices``, padded: what
    :func:`boundary_normals` fits a quadric to.

    Parameters
    ----------
    edges : (E, 2) int array
    n : int
        Number of vertices of the mesh.
    vertices : (b,) int array

    Returns
    -------
    ring : (b, k) int array
        Row ``i``: the two-ring of ``vertices[i]`` (itself left out), padded with
        ``vertices[i]``; ``k`` the largest two-ring.
    member : (b, k) bool array
        False at the padding.

    Examples
    --------
    >>> ring, member = two_rings(np.array([[0, 1], [1, 2], [2, 3]]), 4, np.array([0, 3]))
    >>> ring.tolist(), member.tolist()
    ([[1, 2], [1, 2]], [[True, True], [True, True]])
    """
    one = sp.csr_matrix((np.ones(2 * len(edges)), (edges.ravel(), edges[:, ::-1].ravel())),
                        shape=(n, n))
    reach = sp.csr_matrix(one[vertices] + one[vertices] @ one)
    reach[np.arange(len(vertices)), vertices] = 0.0          # a stored entry: no new one
    reach.eliminate_zeros()
    reach.sort_indices()
    counts = np.diff(reach.indptr)
    k = counts.max()
    member = np.arange(k) < counts[:, None]
    ring = np.repeat(np.asarray(vertices)[:, None], k, axis=1)
    ring[member] = reach.indices
    return ring, member


def boundary_normals(vertices, centres, ring, member, rough):
    """Unit normals at boundary vertices from a quadric fitted to their two-rings: the
    Dirichlet values of ``nu`` (``baselines/README.md``, kll item 5).

    In the frame ``(u_1, u_2, n_0)`` of a vertex ``p`` (``n_0`` its unit area-weighted
    normal ``rough``), least squares of ``w = a u + b v + c u^2 + d u v + e v^2`` over the
    offsets ``(u, v, w)`` of its two-ring from ``p``, weighted by ``1 / |offset|^2``
    (the nearer points count more: the error is 2-4 x smaller on the catenoid); the
    normal is that of the graph at ``p``, ``(n_0 - a u_1 - b u_2) / |...|``. The fit is
    exact on quadrics, so its slope is O(h^2) off on a smooth surface (the cubic terms,
    O(h^3), over a distance h), one-sided as the ring of a boundary vertex is, where
    ``n_0`` is O(h) off.

    Parameters
    ----------
    vertices : (n, 3) float array
    centres : (b,) int array
        The boundary vertices.
    ring, member : (b, k) arrays
        Their :func:`two_rings`.
    rough : (b, 3) float array
        Their unit area-weighted vertex normals.

    Returns
    -------
    (b, 3) float array

    Raises
    ------
    ValueError
        A two-ring of fewer than five vertices (five coefficients to fit), or one on
        which the fit is singular.

    Examples
    --------
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [1, 1, 0]])
    >>> V[:, 2] = 0.5 * V[:, 0] + V[:, 0] ** 2 - V[:, 1] ** 2      # a saddle's graph
    >>> n = boundary_normals(V, np.array([0]), np.array([[1, 2, 3, 4, 5]]),
    ...                      np.ones((1, 5), bool), np.array([[0.0, 0, 1]]))
    >>> ((n * np.sqrt(1.25)).round(12) + 0.0).tolist()               # (-0.5, 0, 1)
    [[-0.5, 0.0, 1.0]]
    """
    small = np.flatnonzero(member.sum(axis=1) < 5)
    if len(small):
        raise ValueError(f"kll's boundary normals (KL8) fit a quadric to the vertices within "
                         f"two edges of each boundary vertex and need five; boundary vertex "
                         f"{int(centres[small[0]])} has {int(member[small[0]].sum())}")
    out = np.empty((len(centres), 3))
    singular = quadric_normals_kernel(
        np.asarray(vertices, dtype=np.float64), np.asarray(centres, dtype=np.int64),
        np.asarray(ring, dtype=np.int64), np.asarray(member, dtype=np.bool_),
        np.ascontiguousarray(rough, dtype=np.float64), out)
    if singular >= 0:
        raise ValueError(f"kll's boundary normals (KL8): the quadric fitted to the two-ring of "
                         f"boundary vertex {int(centres[singular])} is singular (its vertices "
                         f"lie on a curve)")
    return out


@njit(cache=True, error_model="numpy")
def quadric_normals_kernel(vertices, centres, ring, member, rough, out):
    """:func:`boundary_normals` in one pass over the boundary vertices, each fit's five
    weighted normal equations solved by Gaussian elimination with partial pivoting (as
    LAPACK's ``gesv``); numpy's arrays of its formulas to round-off
    (``tests/reference.py::boundary_normals``), without their per-call costs (catenoid
    level 3, 192 boundary vertices: 0.075 ms a call against 0.67 ms, fastest of 300).

    Parameters
    ----------
    vertices : (n, 3) float64 array
    centres : (b,) int64 array
    ring : (b, k) int64 array
    member : (b, k) bool array
        At least five True in each row (checked by the caller).
    rough : (b, 3) float64 array
    out : (b, 3) float64 array, output

    Returns
    -------
    int
        The first row whose normal equations are singular (its ``out`` is NaN), or -1.
    """
    singular = -1
    k = ring.shape[1]
    offsets = np.empty((k, 3))
    gram = np.empty((5, 6))                          # the normal equations, augmented
    slope = np.empty(5)
    for i in range(centres.shape[0]):
        c = centres[i]
        nx, ny, nz = rough[i, 0], rough[i, 1], rough[i, 2]
        best, seed = -1.0, 0
        total, count = 0.0, 0
        for j in range(k):
            for d in range(3):
                offsets[j, d] = vertices[ring[i, j], d] - vertices[c, d]
            ox, oy, oz = offsets[j, 0], offsets[j, 1], offsets[j, 2]
            if member[i, j]:
                sx, sy, sz = oy * nz - oz * ny, oz * nx - ox * nz, ox * ny - oy * nx
                length = np.sqrt(sx * sx + sy * sy + sz * sz)
                if length > best:                       # the first largest, as argmax
                    best, seed = length, j
                total += ox * ox + oy * oy + oz * oz
                count += 1
        ox, oy, oz = offsets[seed, 0], offsets[seed, 1], offsets[seed, 2]
        sx, sy, sz = ny * oz - nz * oy, nz * ox - nx * oz, nx * oy - ny * ox   # rough x seed
        ax, ay, az = sy * nz - sz * ny, sz * nx - sx * nz, sx * ny - sy * nx   # (...) x rough
        length = np.sqrt(ax * ax + ay * ay + az * az)
        ax, ay, az = ax / length, ay / length, az / length                     # u_1
        bx, by, bz = ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax   # u_2
        scale = np.sqrt(total / count)
        gram[:, :] = 0.0
        for j in range(k):
            if not member[i, j]:
                continue
            ox, oy, oz = offsets[j, 0], offsets[j, 1], offsets[j, 2]
            weight = 1.0 / (ox * ox + oy * oy + oz * oz)
            u = (ox * ax + oy * ay + oz * az) / scale
            v = (ox * bx + oy * by + oz * bz) / scale
            w = (ox * nx + oy * ny + oz * nz) / scale
            row = (u, v, u * u, u * v, v * v)
            for p in range(5):
                for q in range(5):
                    gram[p, q] += weight * row[p] * row[q]
                gram[p, 5] += weight * row[p] * w
        solved = True
        for p in range(5):                                # elimination, partial pivoting
            pivot = p
            for q in range(p + 1, 5):
                if abs(gram[q, p]) > abs(gram[pivot, p]):
                    pivot = q
            if gram[pivot, p] == 0.0:
                solved = False
                break
            for q in range(6):
                gram[p, q], gram[pivot, q] = gram[pivot, q], gram[p, q]
            for q in range(p + 1, 5):
                factor = gram[q, p] / gram[p, p]
                for r in range(p, 6):
                    gram[q, r] -= factor * gram[p, r]
        if not solved:
            out[i, :] = np.nan
            singular = i if singular < 0 else singular
            continue
        for p in range(4, -1, -1):                        # back substitution
            y = gram[p, 5]
            for q in range(p + 1, 5):
                y -= gram[p, q] * slope[q]
            slope[p] = y / gram[p, p]
        a, b = slope[0], slope[1]
        mx, my, mz = nx - a * ax - b * bx, ny - a * ay - b * by, nz - a * az - b * bz
        length = np.sqrt(mx * mx + my * my + mz * mz)
        out[i, 0], out[i, 1], out[i, 2] = mx / length, my / length, mz / length
    return singular


def incomplete_lu(S):
    """The incomplete LU factor of ``S`` that :class:`KLLFlow` keeps for the solver's
    BiCGStab (right preconditioner: the residual, hence the stopping test and the
    solution to its tolerance, are those of plain BiCGStab; ``mcfbench/running/solver.py``,
    "Systems").

    ``scipy.sparse.linalg.spilu`` with :data:`ILU` in the matrix's own order (the run's
    locality order; with the solver's minimum-degree order and fill 2, bob at 256 000
    vertices took 4 iterations of 90 ms, in this order 2 of 33 ms) and no row pivoting
    (``diag_pivot_thresh=0``: both permutations the identity).

    Parameters
    ----------
    S : (n, n) scipy.sparse matrix

    Returns
    -------
    SimpleNamespace
        ``L``, ``U`` (n, n) CSR with ``S ~ L U`` (``L`` unit lower triangular), ``perm_r``,
        ``perm_c`` (n,) int arrays, the identity; ``diagonal`` (n,) ``S``'s diagonal,
        against which the flow measures the drift (:data:`DRIFT`).

    Examples
    --------
    >>> S = sp.csr_matrix(np.array([[2.0, -1, 0], [-1, 2, -1], [0, -1, 2]]))
    >>> P = incomplete_lu(S)                        # tridiagonal: no fill, exact
    >>> bool(np.allclose((P.L @ P.U).toarray(), S.toarray())), P.perm_c.tolist()
    (True, [0, 1, 2])
    """
    lu = spla.spilu(sp.csc_matrix(S), permc_spec="NATURAL", diag_pivot_thresh=0.0, **ILU)
    return SimpleNamespace(L=lu.L.tocsr(), U=lu.U.tocsr(), perm_r=lu.perm_r,
                           perm_c=lu.perm_c, diagonal=S.diagonal())


class BlockSystem:
    """(KL6) by its blocks, ``[[I, D], [0, I_4 (x) S]]`` (``baselines/README.md``, "The
    block solve"): the rows of ``(nu, H)`` are four systems with the one matrix ``S``,
    and ``X`` follows from their solution by the substitution (KL7).

    Parameters
    ----------
    S : (n, n) scipy.sparse.csr_matrix
        ``I + dt diag(1/m) L``, shared by the rows ``nu_1, nu_2, nu_3, H``.
    dtH : (n,) float array
        ``dt H*``, the diagonal block of ``X_c`` against ``nu_c``.
    dtnu : (3, n) float array
        ``dt nu*``, the diagonal blocks of ``X_c`` against ``H``.
    preconditioner : SimpleNamespace, optional
        An :func:`incomplete_lu` of ``S`` (or of a nearby ``S``), for the solver's
        BiCGStab.

    Attributes
    ----------
    shared : (n, n) scipy.sparse.csr_matrix
        ``S``.
    preconditioner : SimpleNamespace or None
        The solver's plain ``bicgstab`` takes it as its right preconditioner
        (``mcfbench/running/solver.py``, "Systems").
    rows : int
        4: the last rows of ``b`` (7, n) that ``shared`` solves.
    shape : tuple
        ``(7 n, 7 n)``, of the whole system acting on ``b.ravel()``.

    Examples
    --------
    >>> S = sp.csr_matrix(2.0 * np.eye(2))
    >>> T = BlockSystem(S, np.array([1.0, 0.5]), np.ones((3, 2)))
    >>> T.shape, T.substitute(np.ones((4, 2)), np.full((7, 2), 3.0))[0].tolist()
    ((14, 14), [1.0, 1.5])
    """

    rows = ROWS - 3

    def __init__(self, S, dtH, dtnu, preconditioner=None):
        self.shared, self._dtH, self._dtnu = S, dtH, dtnu
        self.preconditioner = preconditioner
        self.shape = (ROWS * S.shape[0],) * 2

    def substitute(self, y, b):
        """The rows of ``X`` from the solved ``y = (nu, H)`` (4, n) and ``b`` (7, n),
        (KL7): ``X_c = b_c - dt H* nu_c - dt nu*_c H``; (3, n)."""
        return b[:3] - self._dtH * y[:3] - self._dtnu * y[3]

    def tocsr(self):
        """The whole (7n, 7n) matrix of (KL6), for inspection and the tests."""
        n = self.shared.shape[0]
        I, Z = sp.identity(n, format="csr"), None
        top = [[I if d == c else Z for d in range(3)]
               + [sp.diags(self._dtH) if d == c else Z for d in range(3)]
               + [sp.diags(self._dtnu[c])] for c in range(3)]
        below = [[Z] * (3 + r) + [self.shared] + [Z] * (3 - r) for r in range(self.rows)]
        return sp.bmat(top + below, format="csr")


class KLLFlow(VertexFlow):
    """Mean curvature flow by the algorithm of Kovacs, Li and Lubich, (KL6), of one
    surface, closed or with its boundary held fixed (KL8); state ``(X, nu, H)``.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``.
    faces : (m, 3) int array
        Consistently oriented triangles of a manifold surface, closed or with
        boundary (whose vertices keep their place, (KL8)).
    tau : float

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> flow = KLLFlow(V, F, 0.01)
    >>> A, b = flow.system()
    >>> A.shape, A.shared.shape, b.shape, flow.state.shape
    ((28, 28), (4, 4), (7, 4), (7, 4))
    """

    def __init__(self, vertices, faces, tau):
        super().__init__(vertices, faces, tau, mass="barycentric")
        g, n = self.geometry, self.mesh.n_vertices
        nu = unit_vertex_normals(self.faces, g.area_vectors, n)
        H = np.einsum("ic,ic->i", nu, self.assembler.laplacian(g.L_data) @ self.vertices) / g.mass
        if self.fixed.any():                       # (KL8): the Dirichlet values at X^0
            self._boundary = np.flatnonzero(self.fixed)
            self._rings = two_rings(self.mesh.edges, n, self._boundary)
            #: the triangles at the boundary: all that its vertex normals sum
            self._boundary_faces = np.flatnonzero(self.fixed[self.faces].any(axis=1))
            nu[self._boundary] = self.boundary_values(self._X, g.area_vectors)
            H[self._boundary] = 0.0
        self._adopt(np.vstack([self._X, nu.T, H[None]]))
        self._factor = None                        # the kept incomplete_lu, if any

    def preconditioner(self, S):
        """The kept :func:`incomplete_lu` for ``S``, made anew for another shape or a drift
        beyond :data:`DRIFT`; None (and none kept) while ``max_i S_ii <=`` :data:`SPREAD`.
        """
        d = S.diagonal()
        if d.max() <= SPREAD:
            self._factor = None
        elif (self._factor is None or self._factor.diagonal.shape != d.shape
              or (np.abs(d - self._factor.diagonal) > DRIFT * self._factor.diagonal).any()):
            self._factor = incomplete_lu(S)
        return self._factor

    def boundary_values(self, X, area_vectors):
        """``nu`` at the boundary vertices of the surface ``X`` (3, n) with the triangle
        ``area_vectors`` (m, 3), (KL8): :func:`boundary_normals`, (b, 3). The unit vertex
        normals summed over the triangles at the boundary only: at the boundary vertices
        the same sums in the same order."""
        at = self._boundary_faces
        rough = unit_vertex_normals(np.take(self.faces, at, axis=0),
                                    np.take(area_vectors, at, axis=0), self.mesh.n_vertices,
                                    rows=self._boundary)
        return boundary_normals(X.T, self._boundary, *self._rings, rough)

    def _adopt(self, U):
        """Make ``U`` (7, n) the state; ``X`` is a view of its first rows."""
        self._U = np.require(U, np.float64, ["C", "W"])
        self._X = self._U[:3]

    @property
    def state(self):
        """(7, n) read-only view of ``(X^n, nu^n, H^n)``, what :meth:`system` and
        :meth:`advance` work with."""
        view = self._U.view()
        view.flags.writeable = False
        return view

    @property
    def nu(self):
        """(n, 3) read-only view of the evolved normals ``nu^n`` (not normalised)."""
        return self.state[3:6].T

    @property
    def H(self):
        """(n,) read-only view of the evolved mean curvature ``H^n``."""
        return self.state[6]

    def system(self, at=None, base=None, dt=None):
        """``(A, b)`` of (KL6) with the operators at the state ``at`` (7, n).

        Parameters
        ----------
        at, base : (7, n) float arrays, optional
            ``(X*, nu*, H*)`` and ``B``; default the current state.
        dt : float, optional
            Default ``tau``.

        Returns
        -------
        A : BlockSystem
            (KL6) by its blocks (``A.tocsr()`` the (7n, 7n) matrix).
        b : (7, n) float array
        """
        return super().system(self._U if at is None else at, base, dt)

    def _system(self, at, base, dt):
        X, nu, H = (self._X, at[3:6], at[6]) if at is self._U else (at[:3], at[3:6], at[6])
        g, n = self.geometry_at(X), self.mesh.n_vertices
        self._assembles_here = at is self._U     # (VertexFlow.system saw at = U, never None)
        S = self.assembler.row_scaled(g.L_data, g.mass, dt, self.fixed)
        w = curvature_weights(X.T, self.faces, nu.T)[0]
        source = dt * np.divide(w, g.mass, out=np.zeros(n), where=g.mass > 0)
        b = np.array(base, dtype=np.float64)
        dtH, dtnu = dt * H, dt * nu
        if self.fixed.any():                       # (KL8): Dirichlet rows of every block
            dtH, dtnu = np.where(self.fixed, 0.0, dtH), np.where(self.fixed, 0.0, dtnu)
            source[self._boundary] = 0.0
            b[3:6, self._boundary] = self.boundary_values(X, g.area_vectors).T
            b[6, self._boundary] = 0.0
        b[:3] += dtH * nu
        b[3:] += source * at[3:]
        return BlockSystem(S, dtH, dtnu, self.preconditioner(S)), b

    def advance(self, U):
        """Accept ``U`` (7, n) as the state ``n + 1``."""
        self._adopt(U)
        super().advance(self._X)

    def defects(self):
        """:meth:`baselines.vertex_flow.VertexFlow.defects`, and ``"degenerated"`` for
        non-finite normals or curvatures."""
        bad = ~np.isfinite(self._U[3:]).all(axis=0)
        if bad.any():
            return [("degenerated", f"non-finite normal or mean curvature at {int(bad.sum())} "
                     f"vertex(es), e.g. vertex {int(np.flatnonzero(bad)[0])}")]
        return super().defects()
