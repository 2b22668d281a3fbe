"""The sparse factorizations of the shared solver (:mod:`mcfbench.running.solver`):
SuperLU's LU of ``direct`` and its incomplete LU, the ILU methods' preconditioner
in the arrays the compiled kernel (:mod:`mcfbench.running.krylov`) reads."""

import numpy as np

NO_INT = np.zeros(1, dtype=np.uint32)
NO_FLOAT = np.zeros(0)


def unsigned(a):
    """A view (or copy) of a non-negative index array as uint32/uint64."""
    a = np.asarray(a)
    if a.dtype in (np.int32, np.uint32):
        return np.ascontiguousarray(a).view(np.uint32)
    return np.ascontiguousarray(a, dtype=np.int64).view(np.uint64)


LU_ORDERINGS = (
    {"permc_spec": "MMD_AT_PLUS_A", "diag_pivot_thresh": 0.1,
     "options": {"SymmetricMode": True}},
    {"permc_spec": "COLAMD"},
)
"""SuperLU's settings for ``direct``, tried in turn until one gives the tolerance: its
symmetric mode (minimum degree on ``A + A^T``, the diagonal pivot kept unless below 0.1
of its column's largest entry), SuperLU's advice for a (nearly) symmetric pattern with
a strong diagonal as every scheme's (the mesh's graph); then COLAMD with partial
pivoting (scipy's default). One step's matrix (CPU s, fill of L + U), COLAMD against
symmetric mode: BGN, anisotropic sphere level 3 (23 814 unknowns) 0.58 s, 9.5 M
against 0.28 s, 4.5 M; cotan, its level 4 (32 258) 0.30 s, 5.6 M against 0.12 s,
2.2 M; redistributing DDFV, Enneper level 3 (16 361) 0.10 s, 2.3 M against 0.09 s,
1.5 M; every residual before refinement 1e-13 or below."""


ILU_ORDERING = {"permc_spec": "MMD_AT_PLUS_A"}
"""SuperLU's column ordering of the incomplete LU (``spilu``): minimum degree on ``A +
A^T``, for the (nearly) symmetric pattern of every scheme's matrix (the mesh's graph),
with ``drop_tol`` 1e-5 (:func:`ilu_factor`). Against scipy's default (COLAMD, ``drop_tol``
1e-4), anisotropic sphere level 4, ``kept-ilu-bicgstab``, 128 steps (CPU s of the run,
BiCGStab iterations, one factor each): DDFV chord (96 770 unknowns) 15.6 s, 347 -> 9.1 s,
181 (fill of L + U 6.1 M -> 5.3 M; the factor 1.8 -> 1.0 s); redistributing DDFV chord
25.9 s, 456 -> 17.1 s, 337; cotan (32 258) 2.34 s, 297 -> 1.54 s, 128. At ``drop_tol``
1e-4 the ordering alone: 11.9 s, 319; 21.2 s, 458; 1.79 s, 252 (SuperLU's symmetric
mode on top of it: the same iterations)."""


def factorize(A, ilu, drop_tol=1e-5, fill_factor=10.0, ordering=None):
    """SuperLU ``splu``/``spilu`` of ``A``: ``(lu, None)`` or ``(None, detail)``;
    ``ordering``: ``splu``'s settings (one of :data:`LU_ORDERINGS`, default scipy's);
    ``spilu``'s is :data:`ILU_ORDERING`."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla  # on first use (import cost at start-up)

    what = "ILU" if ilu else "LU"
    try:
        with np.errstate(all="ignore"):
            Ac = sp.csc_matrix(A, dtype=float)
            lu = (spla.spilu(Ac, drop_tol=drop_tol, fill_factor=fill_factor, **ILU_ORDERING)
                  if ilu else spla.splu(Ac, **(ordering or {})))
    except RuntimeError as err:      # "Factor is exactly singular"
        return None, f"{what} factorization failed: {str(err).rstrip('.').lower()}"
    return lu, None


def ilu_factor(A, drop_tol=1e-5, fill_factor=10.0):
    """The incomplete LU factor of ``ilu-bicgstab`` (module docstring) of ``A``.

    Parameters
    ----------
    A : (m, m) sparse matrix
        The matrix of the kernel's layout: shared (n, n) or coupled (3n, 3n).
    drop_tol, fill_factor : float
        ``scipy.sparse.linalg.spilu``'s (its ordering :data:`ILU_ORDERING`).

    Returns
    -------
    factor : tuple or None
        ``(dinv, arrays)``: ``dinv`` (m,) the inverse row scaling, ``arrays`` the CSR
        arrays of ``L`` and ``U`` and the permutations (:func:`ilu_arrays`); None
        when both factorizations met an exactly zero pivot.
    detail : str or None
        Why there is no factor.
    """
    import scipy.sparse as sp

    A = sp.csr_matrix(A, dtype=float)
    rows = np.asarray(abs(A).sum(axis=1)).ravel()
    dinv = np.where(rows > 0.0, 1.0 / np.where(rows > 0.0, rows, 1.0), 1.0)
    lu, detail = factorize(sp.diags(dinv) @ A, True, drop_tol, fill_factor)
    if lu is None:                   # an exactly zero pivot: try the rows unscaled
        dinv = np.ones(A.shape[0])
        lu, detail = factorize(A, True, drop_tol, fill_factor)
    return (None, detail) if lu is None else ((dinv, ilu_arrays(lu)), None)


def ilu_arrays(lu):
    """CSR arrays of the ILU factors and the permutations, for the kernel."""
    if lu is None:
        return (NO_INT, NO_INT, NO_FLOAT, NO_INT, NO_INT, NO_FLOAT, NO_INT, NO_INT)
    L, U = lu.L.tocsr(), lu.U.tocsr()
    return (unsigned(L.indptr), unsigned(L.indices), np.ascontiguousarray(L.data, float),
            unsigned(U.indptr), unsigned(U.indices), np.ascontiguousarray(U.data, float),
            unsigned(lu.perm_r), unsigned(lu.perm_c))


def isotropic_ilu_factor(A, k=3, drop_tol=1e-5, fill_factor=10.0):
    """The ILU methods' preconditioner of a coupled (k n, k n) system (BGN, MDR, DeTurck):
    the incomplete LU factor of its isotropic part, applied to each component.

    The coupled matrices of :mod:`baselines.bgn` (B4), :mod:`baselines.mdr` (M5) and
    :mod:`baselines.deturck` (D4) are ``K (x) I_3`` plus a 3 x 3 block at every vertex
    (``omega_k omega_k^T``, ``alpha I + (1 - alpha) nu_k nu_k^T``), unknowns by
    components: their diagonal blocks ``A_cc`` differ only on the diagonal and the
    coupling only joins a vertex's own components. The preconditioner is
    ``M = I_k (x) S`` with ``S = (1/k) sum_c A_cc`` (the trace of every vertex block over
    ``k``: ``K`` plus ``|omega_k|^2 / 3``, ``1 / 3``, ``alpha + (1 - alpha) / 3``): one
    :func:`ilu_factor` of the (n, n) ``S``, which the kernel applies to the k components
    in one pass over the factor (:func:`mcfbench.running.krylov.precondition`).
    Measured (step 1 of the anisotropic sphere, BiCGStab iterations, ``rtol`` 1e-9; these
    with scipy's COLAMD ordering and ``drop_tol`` 1e-4):
    level 3 (23 814 unknowns) BGN 22, MDR 15, DeTurck 8, against 239, 266, 100 with the
    ILU of the coupled matrix (225, -, 118 with its unknowns ordered by vertex), 26, 19,
    11 with one ILU of each diagonal block, and 1000 (not converged), 779, 279
    unpreconditioned; level 4 (96 774) 27, 13, 7 against 46, 26, 12 (each block's ILU)
    and 1000 (not converged), 1000 (not converged), 546.

    ``kept-ilu-bicgstab`` renews it after a solve of ``ilu_refresh`` iterations more than
    the fewest a solve with it took: a new factor of BGN's takes 10-14 every step at
    level 3, so the shared factor's rule (more than ``ilu_refresh``) renewed it at every
    step for nothing (32 steps 5.1 CPU s against 2.6, the same iterations). Whole runs,
    level 4, with :func:`ilu_factor`'s ordering and ``drop_tol`` 1e-5: BGN, MDR, DeTurck
    5.9, 2.4, 2.2 iterations a step, 8.0, 6.1, 7.3 CPU s, against plain BiCGStab's failure
    at step 1 (BGN, MDR; robust re-runs 64, 55 s) and 163 (47 s); Enneper level 3 6.6,
    4.0, 2.8 against 37.5, 28.2, 19.1 (``benchmarks/bench_dumbbell.py --solver``,
    ``mcfbench/README.md``).

    Parameters
    ----------
    A : (k n, k n) sparse matrix
        Unknowns by components (:mod:`mcfbench.running.solver`).
    k : int
        The components.
    drop_tol, fill_factor : float
        ``scipy.sparse.linalg.spilu``'s.

    Returns
    -------
    factor, detail
        :func:`ilu_factor`'s of ``S``.
    """
    import scipy.sparse as sp

    A = sp.coo_matrix(A)
    n = A.shape[0] // k
    diagonal = A.row // n == A.col // n                      # entries of the blocks A_cc
    S = sp.csr_matrix((A.data[diagonal] / k, (A.row[diagonal] % n, A.col[diagonal] % n)),
                      shape=(n, n))                          # duplicates summed
    return ilu_factor(S, drop_tol, fill_factor)
