"""Tangential motion of the F-vertices of least Dirichlet energy: BGN's and MDR's.

The paper's step (2.1), (2.10)-(2.15) gives every F-vertex a velocity whose
normal part is the scheme's discrete ``h . N`` and whose tangential part is
whatever the DDFV Laplacian of the new state has (on real meshes it lets the
F-mesh degenerate, ``ddfv/README.md``). Here the normal displacement of each
F-vertex is kept, and its tangential displacement is chosen as Barrett, Garcke
& Nuernberg (J. Comput. Phys. 222 (2007) 441-467; 227 (2008) 4281-4307; SIAM
J. Sci. Comput. 31 (2008) 225-253; the surface scheme (B1)-(B2) of the
docstring of ``baselines/bgn.py``) or Hu & Li
(Numer. Math. 152 (2022) 127-181, the minimal deformation rate) choose it for
the P1 vertex scheme. Equation labels (TM1)-(TM4) are ours; the derivation
(ours: the papers' texts beyond their abstracts were not available) is in
``ddfv/README.md``, section "Tangential motion of the F-vertices".

The two as constrained minimisations. On the F-mesh ``Gamma^{n-1}`` (the
triangles of the F-vertices of the old state), with ``A`` its P1 (cotangent)
stiffness, ``N_k`` the unit normal at F-vertex ``k`` and ``d_k`` a prescribed
normal displacement, BGN's (B2) for the new positions ``X`` with the test
functions ``eta = phi_k t`` (``t . N_k = 0``) says ``P_k (A X)_k = 0``,
``P_k = I - N_k N_k^T``: the stationarity of the Dirichlet energy of the new
surface among the positions of the given normal displacement (``kappa`` of
(B1)-(B2) is the multiplier of that constraint). MDR's (M1) is the same with
the displacement ``X - X^{n-1}`` in place of ``X``. Both are::

    X = argmin { 1/2 sum_c (Y + X - X^*)_c^T A (Y + X - X^*)_c :
                 N_k . (X_k - X^*_k) = 0 for every k, X_k = X^*_k if k fixed }   (TM1)

    Y = X^*              (BGN: the energy of the new surface)
    Y = X^* - X^{n-1}    (MDR: the energy of the displacement)

where ``X^*`` are the F-vertices of the scheme's step (the constraint keeps
its normal displacement ``d_k = N_k . (X^*_k - X^{n-1}_k)``), ``c`` runs over
the three coordinates. With ``E_k = [t1_k, t2_k]`` (3, 2) an orthonormal
basis of the tangent plane of ``N_k``, ``X_k = X^*_k + E_k s_k`` and (TM1) is
the symmetric positive definite ``2 n x 2 n`` system::

    S s = -r,   S_(k a),(j b) = A_kj t_a,k . t_b,j,   r_(k a) = t_a,k . (A Y)_k   (TM2)

(``S`` is positive definite on a closed surface: ``E s`` constant would be a
vector tangent at every vertex, i.e. zero; at fixed vertices ``s = 0``). Its
solution does not depend on the choice of the bases (a rotation of ``E_k`` is
a change of the unknowns ``s_k``) and moves every F-vertex in the tangent
plane of its normal::

    N_k . (X_k - X^*_k) = 0                                                 (TM3)

T-vertices follow their triangles (:func:`follow_triangles`): with ``lam``
the barycentric coordinates of the projection of ``T^*`` into its triangle of
``X^*``::

    T = T^* + sum_j lam_j (X_j - X^*_j)                                      (TM4)

i.e. ``T - sum_j lam_j X_j = T^* - sum_j lam_j X^*_j``: the T-vertex keeps its
height vector above the point of coordinates ``lam``, so its projection keeps
``lam`` and its height up to the rotation of the triangle (``1 - cos`` of the
angle for the height, ``height x sin`` for the projection).
"""

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from kept_factor import KeptFactorSolver

#: relative residual of (TM2)'s solve (:class:`TangentialMotion`; it was 1e-12)
TANGENTIAL_RTOL = 1e-8

#: CG iterations beyond the fewest a step (at least one), summed since (TM2) was last
#: factorised, after which it is factorised anew (:class:`TangentialMotion`): a
#: factorisation of the dumbbell's level 3 (81 228 unknowns) costs about 70 iterations
#: (1.4 s against 20 ms)
TANGENTIAL_BUDGET = 64

KINDS = ("bgn", "mdr")
"""The tangential motions: ``"bgn"`` (the new surface's Dirichlet energy) and ``"mdr"``
(the displacement's, the minimal deformation rate)."""


def half_cotangents(F, faces):
    """``w_{t,k} = cot(angle_k) / 2`` at every corner ``k`` of every triangle ``t``.

    With ``e_k = F_{k+2} - F_{k+1}`` the edge opposite corner ``k`` (indices mod
    3) and ``2 |t| = |e_1 x e_2|``, ``cot(angle_k) = -e_{k+1} . e_{k+2} / (2 |t|)``:
    the entries ``igl.cotmatrix_entries`` gives (libigl's columns, corner ``k``
    facing the edge ``(k+1, k+2)``), in one compiled pass
    (:func:`ddfv.tangential_kernels.half_cotangents_kernel`), without libigl's
    threads, which spent a step's time waiting on a busy machine (catenoid level
    2: 6.2 ms of wall time and 0.56 ms of CPU a call in a run). Catenoid level 3
    (6 144 triangles): 0.36 ms a call in numpy, 0.07 ms compiled.

    Parameters
    ----------
    F : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (m, 3) float array
    """
    from .kernels import unsigned

    return _half_cotangents(np.asarray(F, dtype=np.float64), unsigned(faces)).T


def _half_cotangents(F, faces):
    """(3, m) :func:`half_cotangents` by corner (row ``k``), ``faces`` uint64."""
    from .tangential_kernels import half_cotangents_kernel

    out = np.empty((3, len(faces)))
    half_cotangents_kernel(F, faces, out)
    return out


class P1Stiffness:
    """The P1 (cotangent) stiffness ``A = -igl.cotmatrix`` of the states of one F-mesh
    (``A_kj = int grad phi_k . grad phi_j``), in a CSR pattern found once.

    :func:`half_cotangents` gives the half cotangents ``w_{t,k} = cot(angle_k) / 2``
    of every corner (the weight of the edge ``(a, b)`` opposite corner ``k`` of
    triangle ``t``); ``A_ab = -sum w``, ``A_aa = A_bb = +sum w`` over the corners
    facing the edge, summed into the slots of a pattern (the edges and the
    diagonal, rows and columns sorted) built on the first call, by one sparse
    product ``data = M w`` with the signed incidence ``M`` (slots x corners,
    built once; a quarter of the cost of the same sums by ``np.bincount``, 0.06
    against 0.26 ms at the catenoid's level 3, 6 144 triangles):
    ``-igl.cotmatrix`` to round-off (both sum in other orders). The pattern
    keeps every edge, also one whose weight vanishes.

    Parameters
    ----------
    faces : (m, 3) int array
    n : int
        Vertices.
    """

    def __init__(self, faces, n):
        from .kernels import unsigned

        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        self._faces = unsigned(self.faces)
        a = self.faces[:, [1, 2, 0]].T                     # (3, m): corner k's edge (a, b)
        b = self.faces[:, [2, 0, 1]].T
        rows = np.concatenate([a, b, a, b]).ravel()
        cols = np.concatenate([b, a, a, b]).ravel()
        keys, slots = np.unique(rows * n + cols, return_inverse=True)
        self._incidence = sp.csr_matrix(
            (np.repeat([-1.0, -1.0, 1.0, 1.0], a.size), (slots, np.tile(np.arange(a.size), 4))),
            shape=(len(keys), a.size))                    # M: (slots, corners), signed
        self.indices = (keys % n).astype(np.int32)
        self.indptr = np.searchsorted(keys // n, np.arange(n + 1)).astype(np.int32)
        self.shape = (n, n)

    def __call__(self, F):
        """``A`` (n, n) CSR at the F-vertices ``F`` (n, 3)."""
        w = _half_cotangents(np.asarray(F, dtype=np.float64), self._faces).ravel()
        # corner k of triangle t at k m + t
        return sp.csr_matrix((self._incidence @ w, self.indices, self.indptr),
                             shape=self.shape)


def tangent_bases(N):
    """Orthonormal bases of the planes orthogonal to the unit vectors ``N``.

    Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin, "Building an
    orthonormal basis, revisited", J. Comput. Graph. Tech. 6(1) (2017): branch-free,
    continuous except across ``N_z = 0``.

    Parameters
    ----------
    N : (n, 3) float array
        Unit vectors.

    Returns
    -------
    t1, t2 : (n, 3) float arrays
        ``(t1, t2, N)`` is a right-handed orthonormal basis at every row.
    """
    x, y, z = np.asarray(N, dtype=float).T
    sign = np.where(z >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + z)
    b = x * y * a
    t1 = np.stack([1.0 + sign * x * x * a, sign * b, -sign * x], axis=1)
    t2 = np.stack([b, sign + y * y * a, -y], axis=1)
    return t1, t2


class TangentialMotion(KeptFactorSolver):
    """(TM1)-(TM3) along a flow, the factor of (TM2) kept from step to step.

    (TM2) changes by ``O(tau)`` from one step to the next, so it is solved with
    the factorisation of an earlier step's matrix
    (:class:`kept_factor.KeptFactorSolver`: sparse Cholesky and conjugate
    gradients, ``S`` being symmetric positive definite; sparse LU and iterative
    refinement otherwise), from the quadratic extrapolation ``3 s^{n-1} - 3 s^{n-2}
    + s^{n-3}`` of the last three steps' solutions (the tangential displacement
    changes smoothly from step to step; catenoid level 2, BGN: 4.3 CG iterations a
    step from the linear extrapolation against 5.5 from ``S_old^{-1} b``; the
    dumbbell's level 3, 40 fresh steps: 4.1 against 4.6 from the linear one),
    until ``|b - S s| <= rtol |b|``. ``S`` is factorised again when a solve takes
    more than ``max_iterations``, and before a solve once the iterations beyond the
    fewest a step (at least one; a fresh factor takes two at the angenent's level
    3), summed since the last factorisation, reach ``budget``
    (:data:`TANGENTIAL_BUDGET`, about what a factorisation costs in iterations: a
    stale factor is kept until it has cost one factorisation more than a fresh
    one would; ``ddfv/README.md``, item 23). The
    iterations apply ``S = E^T A E`` in one compiled pass (:meth:`_operator`);
    ``S`` itself is assembled only to be factorised (:meth:`_system`). The
    unknowns are interleaved, ``(k, a) -> 2 k + a``,
    so that ``S`` has the band of ``A`` in the caller's numbering. For the kept
    factors to fit the next matrix, the tangent bases follow the normals: each
    step's ``t1`` is the last one projected on the new tangent plane (a basis
    from :func:`tangent_bases` where that projection is shorter than 1/2, and at
    the first step), ``t2 = N x t1``. Any ``s`` keeps the normal displacement
    exactly (TM3); the accuracy of ``s`` only decides how close the tangential
    displacement is to the minimiser: its error moves F-vertices within their
    tangent planes, which changes the surface at second order and the next steps
    only through the distribution of the points. Hence the tolerance
    :data:`TANGENTIAL_RTOL` = 1e-8 (it was 1e-12): the records of catenoid level 2
    and sphere level 4 (BGN, MDR) are unchanged to 10 digits, enneper level 2's
    within the spread that the scheme's own solve (BiCGStab, 1e-9) leaves, and a
    step takes 2 CG iterations instead of 4 (catenoid level 2, BGN;
    ``ddfv/README.md``, "Deviations and interpretations").

    Parameters
    ----------
    faces : (m, 3) int array
    kind : {"bgn", "mdr"}
    fixed : (n,) bool array, optional
        Vertices that do not move (Dirichlet); default none.
    rtol : float, optional
        Relative residual of each solve (default :data:`TANGENTIAL_RTOL`).
    max_iterations : int
        CG iterations of a solve with a kept factor before it is factorised anew.
    budget : int or None
        See above (default :data:`TANGENTIAL_BUDGET`; None: only ``max_iterations``).

    Attributes
    ----------
    factorisations, iterations : int
        Factorisations and iterations with a kept factor so far.
    """

    def __init__(self, faces, kind, fixed=None, rtol=None, max_iterations=20,
                 budget=TANGENTIAL_BUDGET):
        if kind not in KINDS:
            raise ValueError(f"unknown tangential motion {kind!r}; choose one of "
                             f"{', '.join(KINDS)}")
        super().__init__(TANGENTIAL_RTOL if rtol is None else rtol, max_iterations,
                         budget=budget, extrapolation=2)
        self.faces, self.kind = faces, kind
        self.fixed = None if fixed is None else np.asarray(fixed, bool)
        self._t1 = None
        self._layout = None
        self._stiffness = None

    def __call__(self, F_old, F_new, N):
        """The F-vertices of (TM1): ``F_new`` moved in the tangent planes of ``N``.

        Parameters
        ----------
        F_old : (n, 3) float array
            The old state ``X^{n-1}``: the surface whose stiffness ``A`` is used.
        F_new : (n, 3) float array
            The scheme's new F-vertices ``X^*`` (their normal displacement is kept).
        N : (n, 3) float array
            Unit normals at the F-vertices (the scheme's, of the old state).

        Returns
        -------
        (n, 3) float array
            ``X`` with ``N_k . (X_k - F_new_k) = 0`` (TM3) and ``X_k = F_new_k`` at
            fixed vertices.
        """
        F_old, F_new = np.asarray(F_old, dtype=float), np.asarray(F_new, dtype=float)
        n = len(F_new)
        free = np.ones(n, bool) if self.fixed is None else ~self.fixed
        rows = None if free.all() else np.flatnonzero(free)
        if self._stiffness is None or self._stiffness.shape[0] != n:
            self._stiffness = P1Stiffness(self.faces, n)
        A = self._stiffness(F_old)
        Y = F_new if self.kind == "bgn" else F_new - F_old
        t1, t2 = self._bases(np.asarray(N, dtype=float))
        if rows is not None:                    # np.take: faster than a boolean mask
            t1, t2 = np.take(t1, rows, axis=0), np.take(t2, rows, axis=0)
        project, apply = self._operator(A, free, t1, t2)
        s = self.solve(-project(A @ Y), apply, lambda: self._system(A, free, (t1, t2)),
                       sequence="s")
        X = F_new.copy()
        D = s[0::2, None] * t1 + s[1::2, None] * t2
        if rows is None:
            X += D
        else:
            X[rows] += D
        return X

    def _operator(self, A, free, t1, t2):
        """``(project, apply)``: ``Z -> E^T Z`` and ``s -> S s = E^T A E s`` of (TM2)
        without forming ``S`` (assembled only when it is factorised, :meth:`_system`).

        ``E`` (3 n, 2 n_free) puts ``s`` into the tangent planes: ``(E s)_k = s_2k t1_k
        + s_2k+1 t2_k`` at the free ``k``, zero at the fixed ones. ``apply`` is one
        compiled pass (:func:`ddfv.tangential_kernels.tangent_product_kernel`; numpy's
        three products, ``E s``, ``A (E s)`` and ``E^T``, bit for bit: catenoid level 3,
        0.18 ms a product in numpy, 0.08 ms compiled).

        Parameters
        ----------
        A : (n, n) sparse matrix
        free : (n,) bool array
        t1, t2 : (n_free, 3) float arrays
            The tangent bases at the free vertices.

        Returns
        -------
        project : callable (n, 3) -> (2 n_free,)
        apply : callable (2 n_free,) -> (2 n_free,)
        """
        from .tangential_kernels import tangent_product_kernel

        rows = None if free.all() else np.flatnonzero(free)
        vertices = (np.arange(len(free)) if rows is None else rows).astype(np.uint64)
        D = np.zeros((len(free), 3))                # E s: zero at the fixed vertices
        A = A.tocsr()
        indptr, indices = (np.asarray(i, dtype=np.int32) for i in (A.indptr, A.indices))
        data = np.asarray(A.data, dtype=np.float64)

        def project(Z):
            Z = Z if rows is None else np.take(Z, rows, axis=0)
            out = np.empty((len(t1), 2))
            out[:, 0] = np.einsum("ij,ij->i", t1, Z)
            out[:, 1] = np.einsum("ij,ij->i", t2, Z)
            return out.ravel()

        def apply(s):
            out = np.empty(2 * len(t1))
            tangent_product_kernel(indptr, indices, data, t1, t2, vertices,
                                   np.asarray(s, dtype=np.float64), D, out)
            return out
        return project, apply

    def _system(self, A, free, bases):
        """The matrix ``S`` of (TM2), unknowns interleaved: ``S_{2k+a, 2j+b} = A_kj
        (t_a[k] . t_b[j])`` over the free ``k, j``, (2 n_free, 2 n_free) CSC.

        ``A`` has the pattern of the mesh at every step, so where its entries go
        in ``S`` is found once (:func:`system_layout`, again if the pattern
        changes): a step multiplies and gathers, without a COO to CSC
        conversion (the same matrix, entry for entry, as assembling it anew).
        """
        if self._layout is None or not (np.array_equal(self._layout.indptr, A.indptr)
                                        and np.array_equal(self._layout.indices, A.indices)):
            self._layout = system_layout(A, free)
        layout = self._layout
        a = A.data[layout.pick]
        # np.take: four times faster than indexing rows of an (n, 3) array
        at_col = [np.take(t, layout.col, axis=0) for t in bases]
        values = np.concatenate([a * np.einsum("ij,ij->i", np.take(t, layout.row, axis=0), tb)
                                 for t in bases for tb in at_col])
        m = 2 * layout.n_free
        return sp.csc_matrix((values[layout.order], layout.system_indices,
                              layout.system_indptr), shape=(m, m))

    def _bases(self, N):
        """``t1, t2`` (n, 3) at the normals ``N``, ``t1`` following the last one (a
        fresh one of :func:`tangent_bases` only where that is shorter than 1/2)."""
        from .tangential_kernels import follow_bases_kernel

        if self._t1 is None or len(self._t1) != len(N):
            t1 = tangent_bases(N)[0]
            t2 = np.cross(N, t1)
        else:
            t1, t2 = np.empty(N.shape), np.empty(N.shape)
            short = np.empty(len(N), dtype=bool)
            if follow_bases_kernel(self._t1, N, t1, t2, short):
                t1[short] = tangent_bases(N[short])[0]
                t2[short] = np.cross(N[short], t1[short])
        self._t1 = t1
        return t1, t2


class SystemLayout(NamedTuple):
    """Where the entries of the stiffness ``A`` go in the matrix ``S`` of (TM2)
    (:func:`system_layout`).

    Attributes
    ----------
    indptr, indices : int arrays
        ``A``'s CSR pattern (the layout holds for it only).
    pick : (q,) int array
        Positions in ``A.data`` of the free-free entries, in the order of ``A[free][:,
        free]`` as COO.
    row, col : (q,) int arrays
        Their rows and columns among the free vertices.
    n_free : int
        Free vertices (``S`` is ``(2 n_free, 2 n_free)``).
    order : (4 q,) int array
        Positions, in the four blocks ``(a, b) = (0, 0), (0, 1), (1, 0), (1, 1)``
        of the entries ``A_kj t_a[k] . t_b[j]`` laid end to end, of ``S``'s
        entries in CSC order.
    system_indices, system_indptr : int arrays
        ``S``'s CSC pattern.
    """

    indptr: np.ndarray
    indices: np.ndarray
    pick: np.ndarray
    row: np.ndarray
    col: np.ndarray
    n_free: int
    order: np.ndarray
    system_indices: np.ndarray
    system_indptr: np.ndarray


def system_layout(A, free):
    """:class:`SystemLayout` of the CSR matrix ``A`` (n, n) on the vertices ``free`` (n,)
    bool: the sparse conversions of an assembly done once, on entry numbers."""
    numbered = sp.csr_matrix((np.arange(1.0, A.nnz + 1), A.indices, A.indptr), shape=A.shape)
    sub = numbered[free][:, free]
    coo = sub.tocoo()
    rows = np.concatenate([2 * coo.row + a for a in (0, 1) for _ in (0, 1)])
    cols = np.concatenate([2 * coo.col + b for _ in (0, 1) for b in (0, 1)])
    m = 2 * sub.shape[0]
    S = sp.csc_matrix((np.arange(1.0, len(rows) + 1), (rows, cols)), shape=(m, m))
    return SystemLayout(A.indptr.copy(), A.indices.copy(), coo.data.astype(np.intp) - 1,
                        coo.row.astype(np.intp), coo.col.astype(np.intp), sub.shape[0],
                        S.data.astype(np.intp) - 1, S.indices, S.indptr)


def tangential_motion(F_old, F_new, faces, N, kind, fixed=None):
    """One step of (TM1)-(TM3): :class:`TangentialMotion` called once.

    Parameters
    ----------
    F_old, F_new, N : (n, 3) float arrays
        See :meth:`TangentialMotion.__call__`.
    faces : (m, 3) int array
    kind : {"bgn", "mdr"}
    fixed : (n,) bool array, optional

    Returns
    -------
    (n, 3) float array
    """
    return TangentialMotion(faces, kind, fixed)(F_old, F_new, N)


def follow_triangles(T, displacement, faces, lam):
    """T-vertices moved with their triangles (TM4).

    Parameters
    ----------
    T : (n_t, 3) float array
    displacement : (n_f, 3) float array
        Displacement of the F-vertices.
    faces : (n_t, 3) int array
    lam : (n_t, 3) float array
        Barycentric coordinates of the T-vertices in their triangles.

    Returns
    -------
    (n_t, 3) float array
        ``T + sum_j lam_j displacement_j``: the offset of ``T`` from the point of
        coordinates ``lam`` of its triangle is kept (one compiled pass,
        :func:`ddfv.tangential_kernels.t_vertices_kernel`).
    """
    from .tangential_kernels import moved_t_vertices

    return moved_t_vertices(displacement, T, faces, lam, carry=False)
