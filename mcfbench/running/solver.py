"""The linear solver shared by every scheme: BiCGStab (van der Vorst 1992,
the paper's [10]), preconditioned variants and a direct LU solve.

Systems
-------
Every scheme solves ``A x = b`` for a (3, n) block ``b`` (one row per
coordinate x, y, z) from an initial guess ``x0``:

* ``A`` of shape (n, n) is SHARED by the three rows (DDFV, cotangent
  schemes): the three systems are solved as ONE system of size 3 n whose
  inner products and norms are Frobenius over the block, and every
  iteration costs two sparse products with the whole block (the three
  rows go through the matrix together, in one pass over its entries);
* ``A`` of shape (3n, 3n) acts on ``b.ravel()`` (C order: all x, then all
  y, then all z; the BGN scheme couples the components);
* ``A`` block upper triangular with an identity leading block (KLL's (KL6),
  ``baselines/README.md``): an object with ``A.shape == (k n, k n)``, an
  (n, n) matrix ``A.shared`` of the last ``A.rows`` (decoupled) rows of
  ``b`` and ``A.substitute(y, b)``, the first rows from their solution ``y``:
  ``A.shared y = b[-A.rows:]`` is solved as a shared system from
  ``x0[-A.rows:]`` (``direct`` factorises ``A.shared`` once for its rows),
  ``[A.substitute(y, b); y]`` returned; iterations, residual and stopping
  test are the shared system's (the substituted rows' residual is round-off).
  An ``A.preconditioner`` (an incomplete LU, as ``spilu``'s, that the system keeps:
  KLL's ``S`` where its diagonal spreads, ``baselines.kll.SPREAD``) turns plain
  ``bicgstab`` into ``ilu-bicgstab`` with it (``SolveInfo.method`` says which ran).

Iteration count
---------------
One iteration is one pass of the BiCGStab loop (two products with ``A``,
for the preconditioned methods also two preconditioner solves); an exit in
its middle (``|s|`` already small) counts as a whole iteration. A solve
that is converged at ``x0`` counts 0. ``direct`` counts 0. The extra
product of a true-residual check (below) is not an iteration.

Stopping test
-------------
``|b - A x| <= rtol |b - A c|`` (Frobenius norms), ``c`` the per-row
(per-component) mean of ``x0`` broadcast over the points. It is invariant
under translation (``A`` with row sums one: ``b -> b + k``, ``x0 -> x0 +
k``) and scaling of the surface: for DDFV and cotangent systems ``A c = c``
and ``|b - A c|`` is the size of the positions measured from their
centroid. For a surface centred at the origin (the sphere of Table 3.1) it
equals ``|b|`` up to round-off. ``SolveInfo.residual`` is ``|r|`` over that
reference. If ``b - A c`` vanishes to round-off (below ``(nnz_row + 1) eps
| |b| + |A| |c| |``), ``c`` solves the system to working precision and is
returned (0 iterations, residual 0).

The iterations test the recurrence residual. When the tolerance is within
1000 times the round-off estimate ``eps (|A|_inf |x| + |b| + max_k |r_k|)``
the true residual ``b - A x`` is computed before accepting (one more
product); if it misses the tolerance the iteration restarts from it
(residual replacement). At ``rtol = 1e-9`` on the sphere this never
happens, so the iterates are those of the plain recurrence.

Failures (``SolveInfo.status``)
------------------------------
``breakdown``
    A Krylov breakdown: ``rho = (r_hat, r) = 0``, ``(r_hat, v) = 0``,
    ``omega = 0`` (``(t, s) = 0``) or ``t = A s = 0``, exactly; or a
    scalar or the residual overflowed. Also non-finite input (NaN/inf in
    ``b``, ``x0`` or ``A``) and an exactly singular factorization
    (``direct``, ``ilu-bicgstab``). ``SolveInfo.detail`` says which.
    (Tests "zero to round-off", ``|rho| <= eps |r_hat| |r|``, stopped many
    solves on bad meshes that the exact tests let converge.)
``stagnated``
    The residual cannot get below the tolerance in double precision: the
    true residual stays above it after a residual replacement, or the
    recurrence residual set no new minimum in the last
    ``stagnation_window`` iterations while that minimum is within 1000
    ``eps | |b| + |A| |x| |`` (the round-off floor of ``b - A x``).
    ``direct``: the residual is above ``rtol`` after iterative refinement
    (ill-conditioned matrix). A residual that just wanders far above the
    floor is not stagnation: it runs into ``maxiter``.
``max_iterations``
    ``maxiter`` iterations without meeting the tolerance.

No arithmetic exception or warning escapes: the iteration is one compiled function
(numba, ``error_model="numpy"``), every scalar checked, the failures above reported in
``SolveInfo``; :class:`Solver` raises :class:`SolverFailure` for them.

Methods (:data:`METHODS`)
-------------------------
``bicgstab``
    The paper's unpreconditioned BiCGStab (default): the former numpy implementation's
    iteration counts, iterates within round-off (icosphere levels 1-5, Table 3.1's
    setting: 8/45/113/279/654 iterations every solve, solutions within 3e-16).
``jacobi-bicgstab``
    Right-preconditioned with the diagonal of ``A`` (one more vector pass a product).
``coupled-jacobi-bicgstab``
    ``jacobi-bicgstab`` for a coupled ``A`` (BGN, MDR, DeTurck), else ``bicgstab``.
``ilu-bicgstab``
    BiCGStab right-preconditioned with an incomplete LU factorization
    (``scipy.sparse.linalg.spilu``, minimum degree on ``A + A^T``,
    :data:`~mcfbench.running.factorizations.ILU_ORDERING`; ``drop_tol``/``fill_factor``
    from :class:`Solver`, 1e-5 and 10) of ``D^{-1} A``, ``D`` the absolute row sums (rows
    equilibrated; if that factor is exactly singular, of ``A`` itself), once per call;
    compiled triangular solves. A coupled ``A`` (BGN, MDR, DeTurck): the factor of its
    isotropic part (:func:`~mcfbench.running.factorizations.isotropic_ilu_factor`).
``kept-ilu-bicgstab``
    ``ilu-bicgstab`` with the factor kept by the :class:`Solver` across its calls (a
    run's steps: the matrices of nearby steps are nearby) and renewed when a solve
    with it took more than ``ilu_refresh`` iterations (a coupled system's: more than the
    fewest it took plus these), for another shape, or when it did not converge (then the
    solve is repeated from ``x0`` with the new factor, iterations summed); through
    :func:`solve` alone ``ilu-bicgstab``. Anisotropic sphere level 4, DDFV chord: one
    factor (1.0 s) for the run's 128 steps, 1.4 iterations a step (plain BiCGStab
    170-290; pyamg's AMG 40-95: ``mcfbench/README.md``, "A problem's own solver").
``direct``
    Sparse LU (``scipy.sparse.linalg.splu``: SuperLU's symmetric mode, then COLAMD with
    partial pivoting if that misses the tolerance, :data:`LU_ORDERINGS`) once per call for
    the k rows or ``b.ravel()``; up to three refinement steps, residual as above.
``jacobi-direct``
    ``jacobi-bicgstab``, then ``direct`` from ``x0`` if that fails (:data:`ROBUST`):
    it converges wherever ``direct`` does (iterations: Jacobi's, failed included).

Right preconditioning leaves the residual, hence the stopping test, unchanged. On
cotangent systems of bad meshes (perturbed, random-point, anisotropic, marching-cubes
surfaces, 6k-16k vertices, ``tau`` = 1, 100, 10^4 times the mean vertex area, ``rtol =
1e-9``, ``maxiter = 1000``) ``bicgstab`` converged in 20 of 36, ``jacobi-bicgstab`` in
33, the others in all 36. On well-shaped meshes ``bicgstab`` is by far the cheapest
(level-5 sphere: 13 ms a step against 0.4-1 s for the factorizations).
"""

import math
from dataclasses import dataclass, field, replace

import numpy as np

from mcfbench.running.factorizations import (LU_ORDERINGS, NO_FLOAT, factorize, ilu_arrays,
                                             ilu_factor, isotropic_ilu_factor, unsigned)

# scipy.sparse, the compiled kernels (numba) and the thread checks are imported on
# first use: the command line reads METHODS and ROBUST for its help in 0.1 s.

METHODS = ("bicgstab", "jacobi-bicgstab", "coupled-jacobi-bicgstab", "ilu-bicgstab",
           "kept-ilu-bicgstab", "direct", "jacobi-direct")
ROBUST = "jacobi-direct"
"""The method for meshes of unknown quality: its LU converged on all 36 bad-mesh systems
(BiCGStab on 20, Jacobi's on 33). BGN's first step on the anisotropic sphere's level 4:
1.23 s (367 Jacobi iterations) against ``direct``'s 3.81 s; plain BiCGStab fails."""
STATUSES = ("converged", "max_iterations", "breakdown", "stagnated")

_REFINEMENTS = 3         # iterative refinement steps of "direct"


@dataclass(frozen=True)
class SolveInfo:
    """Outcome of one solve.

    Attributes
    ----------
    iterations : int
        Iterations (see the module docstring): loop passes, a half-step exit
        counts as one, 0 when ``x0`` already meets the tolerance, 0 for
        ``direct``.
    residual : float
        Final relative residual ``|b - A x| / |b - A c|`` (module docstring);
        NaN when it could not be computed (non-finite input).
    converged : bool
    status : str
        One of :data:`STATUSES`.
    method : str
        One of :data:`METHODS`.
    detail : str
        What went wrong (which quantity broke down, the iteration limit, the
        stagnation criterion); empty when converged.
    """

    iterations: int
    residual: float
    converged: bool
    status: str = "converged"
    method: str = "bicgstab"
    detail: str = ""


# ---------------------------------------------------------------------------
# Python side: layouts, reports (factorizations: mcfbench.running.factorizations)


def _csr(A):
    """``(indptr, indices, data)`` of ``A`` as CSR, the index arrays unsigned views."""
    import scipy.sparse as sp

    if not (sp.issparse(A) and A.format == "csr"):
        if not sp.issparse(A):
            A = np.asarray(A, dtype=float)
            if A.ndim != 2:
                raise ValueError(f"A must be a 2-D matrix, got shape {A.shape}")
        A = sp.csr_matrix(A)
    return unsigned(A.indptr), unsigned(A.indices), np.ascontiguousarray(A.data, np.float64)


def _coupled(A, shape):
    """False for an (n, n) ``A`` shared by the k rows of a (k, n) block, True
    for a (k n, k n) one acting on its ravel."""
    k, n = shape
    if A.shape == (n, n):
        return False
    if A.shape == (k * n, k * n):
        return True
    raise ValueError(f"A has shape {A.shape}; for b of shape {shape} it must be "
                     f"({n}, {n}) (shared by the rows) or ({k * n}, {k * n}) (coupled)")


def _blocks(A, b, x0, overwrite_x0=False):
    """``b``, a copy of ``x0`` (``x0`` itself with ``overwrite_x0`` when it is a
    C-contiguous float64 array not sharing memory with ``b``), ``c`` in the
    kernels' (k, m) layout.

    Returns ``(b, x, cmean, cfull, to_block)``: ``cmean`` the per-row means
    of ``x0``, ``cfull`` the broadcast ``c`` for a coupled matrix (empty for
    a shared one), ``to_block`` maps a (k, m) result back to ``b``'s shape.
    """
    b = np.ascontiguousarray(b, dtype=float)
    if b.ndim != 2:
        raise ValueError(f"b must be a (k, n) block, got shape {b.shape}")
    if x0 is None:
        x = np.zeros(b.shape)
    elif (overwrite_x0 and isinstance(x0, np.ndarray) and x0.dtype == np.float64
          and x0.flags.c_contiguous and x0.flags.writeable
          and not np.shares_memory(x0, b)):
        x = x0                       # the caller's buffer: no copy
    else:
        x = np.array(x0, dtype=float, order="C", copy=True)
    if x.shape != b.shape:
        raise ValueError(f"x0 has shape {x.shape}, b has {b.shape}")
    k, n = b.shape
    coupled = _coupled(A, b.shape)
    # x.mean(axis=1) without its Python wrapper (the same sum and division; solve()'s errstate)
    cmean = np.add.reduce(x, axis=1) / n if n else np.zeros(k)
    if not coupled:
        return b, x, cmean, np.empty((k, 0)), lambda z: z
    cfull = np.repeat(cmean, n).reshape(1, k * n)
    return (b.reshape(1, k * n), x.reshape(1, k * n), cmean, cfull,
            lambda z: z.reshape(k, n))


def _failed(method, status, detail, residual=math.nan, iterations=0):
    return SolveInfo(int(iterations), float(residual), False, status, method, detail)


def solve(A, b, x0=None, *, method="bicgstab", rtol=1e-9, maxiter=1000,
          stagnation_window=50, ilu_drop_tol=1e-5, ilu_fill_factor=10.0, overwrite_x0=False,
          threads=1, factor=None):
    """Solve ``A x = b`` for a (k, n) block ``b`` from ``x0``; reports failures in ``info``.

    Parameters
    ----------
    A : (n, n) or (k n, k n) scipy sparse matrix (or dense array), or block triangular
        Shared by the k rows of ``b``, acting on ``b.ravel()``, or an object with
        ``shared``, ``rows`` and ``substitute`` (module docstring).
    b, x0 : (k, n) float arrays
        ``x0=None`` starts from zero.
    method : str
        One of :data:`METHODS`.
    rtol : float
        ``|b - A x| <= rtol |b - A c|`` (module docstring).
    maxiter : int
    stagnation_window : int
        Stagnated after this many iterations without a new residual minimum.
    ilu_drop_tol, ilu_fill_factor : float
        ``spilu`` parameters of ``"ilu-bicgstab"``.
    overwrite_x0 : bool
        ``x0`` may be used as the iterate (no copy) when it is a C-contiguous,
        writeable float64 array not sharing memory with ``b``; it then holds
        the returned solution (or the last iterate).
    threads : int
        Threads of the BiCGStab methods' products and vector updates (row
        blocks, :func:`kept_factor.threads.for_threads`), at most
        ``numba.config.NUMBA_NUM_THREADS``. With more than one the inner
        products are summed in another order: the iterates agree to
        round-off, not bitwise.
    factor : tuple, optional
        The ILU methods' preconditioner, an :func:`ilu_factor` of this or another
        matrix of the same shape (of ``A.shared`` for a block triangular ``A``, an
        :func:`isotropic_ilu_factor` for a coupled one), instead of one of ``A``.

    Returns
    -------
    x : (k, n) float array
        The solution; when not converged the last iterate (``x0`` when
        nothing could be computed).
    info : SolveInfo

    Raises
    ------
    ValueError
        Unknown method or shapes that do not fit together.
    """
    import scipy.sparse as sp

    from kept_factor.threads import check_threads, for_threads
    from mcfbench.running import krylov

    if method not in METHODS:
        raise ValueError(f"unknown solver method {method!r}; choose one of "
                         f"{', '.join(METHODS)}")
    if hasattr(A, "substitute"):             # block triangular (module docstring)
        return _by_blocks(A, b, x0, method=method, rtol=rtol, maxiter=maxiter,
                          stagnation_window=stagnation_window, ilu_drop_tol=ilu_drop_tol,
                          ilu_fill_factor=ilu_fill_factor, overwrite_x0=overwrite_x0,
                          threads=threads, factor=factor)
    check_threads(threads)
    with np.errstate(all="ignore"):      # one for the whole solve (2.4 us each)
        b, x, cmean, cfull, to_block = _blocks(A, b, x0, overwrite_x0)
        csr = _csr(A)
        if method == "direct":
            x, info = _direct(A, csr, b, x, cmean, cfull, rtol)
            return to_block(x), info
        if method == "jacobi-direct":
            start = x.copy()
            x, info = solve(A, to_block(b), to_block(x), method="jacobi-bicgstab",
                            rtol=rtol, maxiter=maxiter, stagnation_window=stagnation_window,
                            overwrite_x0=True, threads=threads)
            if not info.converged:
                x, lu = _direct(A, csr, b, start, cmean, cfull, rtol)
                info = replace(lu, iterations=info.iterations)
            return to_block(x), replace(info, method=method)
        kind, dinv, lu = 0, NO_FLOAT, None
        if method == "jacobi-bicgstab" or (method == "coupled-jacobi-bicgstab" and cfull.size):
            kind = 1
            d = sp.csr_matrix(A).diagonal().astype(float)
            dinv = np.where(d != 0.0, 1.0 / np.where(d != 0.0, d, 1.0), 1.0)
        elif method in ("ilu-bicgstab", "kept-ilu-bicgstab"):
            if np.isfinite(csr[2]).all() and np.isfinite(b).all() and np.isfinite(x).all():
                kind = 2
                if factor is None:
                    spilu = (ilu_drop_tol, ilu_fill_factor)      # k rows: len(cmean)
                    factor, detail = (isotropic_ilu_factor(A, len(cmean), *spilu)
                                      if cfull.shape[1] else ilu_factor(A, *spilu))
                    if factor is None:
                        return to_block(x), _failed(method, "breakdown", detail)
                dinv, lu = factor
            # else: kind 0, the kernel reports the non-finite input
        # the residual pass stays serial: its threaded copy had no loop numba could split
        kernel = for_threads(krylov.bicgstab_kernel, threads, spmv=krylov.spmv)
        code, dcode, it, rnorm, ref = kernel(
            *csr, b, x, cmean, cfull, float(rtol), int(maxiter), int(stagnation_window),
            kind, dinv, *(lu or ilu_arrays(None)))
        residual = (rnorm / ref if ref > 0.0 else
                    0.0 if rnorm == 0.0 else math.nan if math.isnan(ref) else math.inf)
    detail = ""
    if code == krylov.MAXITER:
        detail = f"iteration limit {maxiter} reached"
    elif code == krylov.STAGNATED:
        detail = (f"stagnation: no new residual minimum in the last {stagnation_window} "
                  "iterations, at the round-off floor" if dcode == 1 else
                  "stagnation: the true residual stays above the tolerance at the "
                  "round-off floor")
    elif code == krylov.BREAKDOWN:
        detail = krylov.BREAKDOWN_DETAILS[dcode]
    return to_block(x), SolveInfo(int(it), float(residual), code == krylov.CONVERGED,
                                  krylov.STATUS_NAMES[code], method, detail)


def _by_blocks(A, b, x0, **options):
    """:func:`solve` for a block triangular ``A`` (module docstring): the shared rows,
    then the substitution."""
    b = np.asarray(b, dtype=float)
    if b.ndim != 2 or A.shape != (b.size, b.size) or b.shape[0] <= A.rows:
        raise ValueError(f"A is block triangular of shape {A.shape} with {A.rows} shared "
                         f"rows; b has shape {b.shape}")
    if x0 is not None and np.shape(x0) != b.shape:
        raise ValueError(f"x0 has shape {np.shape(x0)}, b has {b.shape}")
    rows = slice(b.shape[0] - A.rows, None)
    kept = getattr(A, "preconditioner", None)
    if kept is not None and options["method"] == "bicgstab" and options["factor"] is None:
        options.update(method="ilu-bicgstab", factor=(np.ones(A.shared.shape[0]),
                                                      ilu_arrays(kept)))
    y, info = solve(A.shared, b[rows], None if x0 is None else np.asarray(x0)[rows],
                    **options)
    return np.vstack([A.substitute(y, b), y]), info


def _direct(A, csr, b, x0, cmean, cfull, rtol):
    """LU solve in the (k, m) layout, iterative refinement, residual check."""
    from mcfbench.running import krylov

    method = "direct"
    r = np.empty_like(b)
    _, ref2, _, _, _, bad, cfloor = krylov.residual(*csr, b, x0, cmean, cfull, r)
    if bad:
        return x0, _failed(method, "breakdown", krylov.BREAKDOWN_DETAILS[bad])
    ref = math.sqrt(ref2)
    if ref <= cfloor:                # A c = b up to round-off: c is the solution
        x = np.empty_like(b)
        x[...] = cmean[:, None] if cfull.shape[1] == 0 else cfull
        return x, SolveInfo(0, 0.0, True, "converged", method)
    for ordering in LU_ORDERINGS:    # the last one's failure is the answer
        lu, detail = factorize(A, False, ordering=ordering)
        if lu is None:
            x, info = x0, _failed(method, "breakdown", detail)
            continue
        x, info = _refined(lu, csr, b, x0, cmean, cfull, ref, rtol, r)
        if info.converged:
            break
    return x, info


def _refined(lu, csr, b, x0, cmean, cfull, ref, rtol, r):
    """The LU solution of ``b`` (k, m), iteratively refined to ``rtol`` (:func:`_direct`)."""
    from mcfbench.running import krylov

    method = "direct"

    def lu_solve(rhs):               # the k rows at once
        return np.ascontiguousarray(lu.solve(np.ascontiguousarray(rhs.T)).T)

    x = lu_solve(b)
    best = math.inf
    for step in range(_REFINEMENTS + 1):
        rr, *_ = krylov.residual(*csr, b, x, cmean, cfull, r)
        res = math.sqrt(rr) / ref
        if not math.isfinite(res):
            return x0, _failed(method, "breakdown",
                               "LU solution is not finite (numerically singular matrix)")
        if res <= rtol:
            return x, SolveInfo(0, res, True, "converged", method)
        if step == _REFINEMENTS or res >= 0.5 * best:
            break
        best = res
        x = x + lu_solve(r)
    return x, _failed(method, "stagnated",
                      f"residual above rtol after the LU solve and {step} refinement "
                      "step(s): the matrix is too ill-conditioned", res)


def apply_block(A, X, out=None):
    """``A`` applied to the (k, n) block ``X`` (into ``out`` if given).

    ``A`` is (n, n), applied to every row, or (k n, k n), applied to
    ``X.ravel()``: one compiled pass over the entries of ``A`` for all rows,
    each entry bitwise that of scipy's ``A @ x``.
    """
    from mcfbench.running import krylov

    X = np.ascontiguousarray(X, dtype=float)
    if X.ndim != 2:
        raise ValueError(f"X must be a (k, n) block, got shape {X.shape}")
    shape = (1, X.size) if _coupled(A, X.shape) else X.shape
    into = (out is not None and out.shape == X.shape and out.dtype == np.float64
            and out.flags.c_contiguous and not np.shares_memory(out, X))
    Y = out if into else np.empty_like(X)
    Yi = Y.reshape(shape)
    krylov.spmv(*_csr(A), X.reshape(shape), Yi, Yi)
    if out is not None and not into:
        out[...] = Y
        return out
    return Y


class SolverFailure(RuntimeError):
    """A linear solve that did not converge; ``info`` says how.

    Attributes
    ----------
    info : SolveInfo
    status : str
        ``solver_failed`` (iteration limit), ``solver_breakdown`` (Krylov
        breakdown, singular factorization, non-finite input) or
        ``solver_stagnated``.
    """

    STATUS = {"max_iterations": "solver_failed", "breakdown": "solver_breakdown",
              "stagnated": "solver_stagnated"}

    def __init__(self, info, rtol, maxiter):
        self.info = info
        self.status = self.STATUS.get(info.status, "solver_failed")
        what = info.detail or {"max_iterations": f"iteration limit {maxiter} reached",
                               "breakdown": "Krylov breakdown",
                               "stagnated": "residual stagnated"}.get(info.status, info.status)
        residual = (f"relative residual {info.residual:.3e} > rtol {rtol:.1e}"
                    if math.isfinite(info.residual) and info.residual > rtol
                    else f"relative residual {info.residual:.3e}, rtol {rtol:.1e},")
        super().__init__(f"{info.method} did not converge ({what}): {residual} after "
                         f"{info.iterations} iterations")


@dataclass(frozen=True)
class Solver:
    """The linear solver shared by every scheme: ``solver(A, b, x0) -> (x, info)``.

    Raises :class:`SolverFailure` when the solve does not converge.

    Parameters
    ----------
    method : str
        One of :data:`METHODS` (module docstring); default the paper's
        ``"bicgstab"``.
    rtol : float
        Relative tolerance, ``|b - A x| <= rtol |b - A c|``.
    maxiter : int
        Iteration limit per solve.
    stagnation_window : int
        Iterations without a new residual minimum that count as stagnation.
    ilu_drop_tol, ilu_fill_factor : float
        ``scipy.sparse.linalg.spilu`` parameters of the ILU methods.
    threads : int
        Threads of the BiCGStab products and vector updates (see :func:`solve`).
    ilu_refresh : int
        ``"kept-ilu-bicgstab"``: the kept factor is renewed after a solve that took
        more iterations (module docstring). Default 10: at the anisotropic sphere's
        level 4 (DDFV) ten iterations with the factor cost about 0.25 s, a new factor
        1.0 s, after which a step takes 1-2.
    """

    method: str = "bicgstab"
    rtol: float = 1e-9
    maxiter: int = 1000
    stagnation_window: int = 50
    ilu_drop_tol: float = 1e-5
    ilu_fill_factor: float = 10.0
    threads: int = 1
    ilu_refresh: int = 10
    _kept: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    #: ``solver(A, b, x0, overwrite_x0=True)`` iterates in ``x0`` (no copy), see :func:`solve`
    can_overwrite_x0 = True

    @classmethod
    def of_settings(cls, settings):
        """The solver of a run's settings (the one function from settings to solver).

        Two shapes: nested, ``settings["solver"] = {"method", "rtol", "maxiter"}`` (the
        matrix's records); flat, ``rtol`` with optional ``maxiter`` and ``threads``, and
        ``solver`` the method when given (Table 3.1's, the beyond study's, the gallery's).
        """
        spec = settings.get("solver")
        if isinstance(spec, dict):
            return cls(**spec)
        flat = {k: settings[k] for k in ("rtol", "maxiter", "threads") if k in settings}
        return cls(**flat) if spec is None else cls(method=spec, **flat)

    def __post_init__(self):
        from kept_factor.threads import check_threads

        if self.method not in METHODS:
            raise ValueError(f"unknown solver method {self.method!r}; choose one of "
                             f"{', '.join(METHODS)}")
        if not (isinstance(self.rtol, (int, float)) and 0 < self.rtol < 1):
            raise ValueError(f"rtol must lie in (0, 1), got {self.rtol!r}")
        for name in ("maxiter", "stagnation_window", "ilu_refresh"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, np.integer)) \
                    or value < 1:
                raise ValueError(f"{name} must be a whole number >= 1, got {value!r}")
        if not (isinstance(self.ilu_drop_tol, (int, float)) and 0 <= self.ilu_drop_tol < 1):
            raise ValueError(f"ilu_drop_tol must lie in [0, 1), got {self.ilu_drop_tol!r}")
        if not (isinstance(self.ilu_fill_factor, (int, float))
                and self.ilu_fill_factor >= 1):
            raise ValueError(f"ilu_fill_factor must be >= 1, got {self.ilu_fill_factor!r}")
        check_threads(self.threads)

    def __call__(self, A, b, x0, *, overwrite_x0=False):
        options = dict(method=self.method, rtol=self.rtol, maxiter=self.maxiter,
                       stagnation_window=self.stagnation_window,
                       ilu_drop_tol=self.ilu_drop_tol, ilu_fill_factor=self.ilu_fill_factor,
                       threads=self.threads)
        if self.method == "kept-ilu-bicgstab":
            x, info = self._with_kept_factor(A, b, x0, overwrite_x0, options)
        else:
            x, info = solve(A, b, x0, overwrite_x0=overwrite_x0, **options)
        if not info.converged:
            raise SolverFailure(info, self.rtol, self.maxiter)
        return x, info

    def _with_kept_factor(self, A, b, x0, overwrite_x0, options):
        """:func:`solve` with the kept ILU factor (``"kept-ilu-bicgstab"``, module
        docstring): renewed for another shape, after a solve of more than
        :attr:`ilu_refresh` iterations, and when a solve with it fails (then
        repeated from ``x0``)."""
        shared = A.shared if hasattr(A, "substitute") else A
        k, n = np.shape(b)[0], np.shape(b)[-1]       # not a (k, n) block: solve() says so
        coupled = shared.shape != (n, n)
        spilu = (self.ilu_drop_tol, self.ilu_fill_factor)
        kept = self._kept
        old = kept.get("shape") == shared.shape and not kept.get("stale", True)
        if old:
            start = None if x0 is None else np.array(x0, dtype=float)
        else:
            kept["factor"], _ = (isotropic_ilu_factor(shared, k, *spilu) if coupled
                                 else ilu_factor(shared, *spilu))
            kept["shape"] = shared.shape     # no factor: solve() says why (input, pivot)
            kept["fewest"] = math.inf
        x, info = solve(A, b, x0, overwrite_x0=overwrite_x0, factor=kept["factor"],
                        **options)
        if old and not info.converged:
            kept["stale"] = True
            x, again = self._with_kept_factor(A, b, start, True, options)
            return x, replace(again, iterations=info.iterations + again.iterations)
        kept["fewest"] = min(kept["fewest"], info.iterations) if coupled else 0
        kept["stale"] = info.iterations > self.ilu_refresh + kept["fewest"]
        return x, info
