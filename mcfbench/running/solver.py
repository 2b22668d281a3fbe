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
  y, then all z; the BGN scheme couples the components).

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

No arithmetic exception or warning escapes: the whole iteration is one
compiled function (numba, ``error_model="numpy"``), every scalar is
checked, and the failures above are reported in ``SolveInfo``;
:class:`Solver` raises :class:`SolverFailure` for them.

Methods (:data:`METHODS`)
-------------------------
``bicgstab``
    The paper's unpreconditioned BiCGStab (default). Its iteration counts
    are those of the former numpy implementation and its iterates agree to
    round-off (icosphere levels 1-5, Table 3.1 setting: 8/45/113/279/654
    iterations, every solve the same count, solutions within 3e-16).
``jacobi-bicgstab``
    BiCGStab right-preconditioned with the diagonal of ``A``. Costs one
    extra vector pass per product.
``ilu-bicgstab``
    BiCGStab right-preconditioned with an incomplete LU factorization
    (``scipy.sparse.linalg.spilu``, ``drop_tol``/``fill_factor`` from
    :class:`Solver`) of ``D^{-1} A``, ``D`` the absolute row sums (rows
    equilibrated; if that factor is exactly singular, of ``A`` itself),
    computed once per call (once for the three rows in the shared case);
    the triangular solves are compiled.
``direct``
    Sparse LU (``scipy.sparse.linalg.splu``, COLAMD ordering) factorized
    once per call and applied to the three rows (shared case) or to
    ``b.ravel()``; up to three steps of iterative refinement, the residual
    checked as above.

Right preconditioning leaves the residual, hence the stopping test,
unchanged. Measured on cotangent systems of bad meshes (perturbed,
random-point, anisotropic, marching-cubes surfaces, 6k-16k vertices,
``tau`` = 1, 100, 10^4 times the mean vertex area, ``rtol = 1e-9``,
``maxiter = 1000``): ``bicgstab`` converged in 20 of 36 systems,
``jacobi-bicgstab`` in 33, ``ilu-bicgstab`` and ``direct`` in all 36.
On well-shaped meshes ``bicgstab`` is by far the cheapest (level-5 sphere:
about 13 ms per step against 0.4-1 s for the factorizations).
"""

import math
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numba import njit, prange

from ddfv.kernels import check_threads, for_threads

METHODS = ("bicgstab", "jacobi-bicgstab", "ilu-bicgstab", "direct")
ROBUST = "direct"
"""The method for meshes of unknown quality: it converged on every bad-mesh system
measured (36 of 36 cotangent systems, against 20 for plain BiCGStab)."""
STATUSES = ("converged", "max_iterations", "breakdown", "stagnated")

_EPS = float(np.finfo(float).eps)
_TRUST = 1e3             # trust the recurrence residual when tol >= _TRUST * round-off floor
_REFINEMENTS = 3         # iterative refinement steps of "direct"

# status codes of the compiled kernel
_CONVERGED, _MAXITER, _BREAKDOWN, _STAGNATED = 0, 1, 2, 3
_STATUS = {_CONVERGED: "converged", _MAXITER: "max_iterations", _BREAKDOWN: "breakdown",
           _STAGNATED: "stagnated"}
# what broke down (detail codes of the kernel)
_DETAIL = {
    1: "Krylov breakdown: rho = (r_hat, r) = 0",
    2: "Krylov breakdown: (r_hat, v) = 0",
    3: "Krylov breakdown: omega = 0 ((t, s) = 0)",
    4: "Krylov breakdown: omega undefined (t = A s = 0)",
    5: "Krylov breakdown: alpha = rho / (r_hat, v) overflowed",
    6: "Krylov breakdown: omega or beta overflowed",
    7: "Krylov breakdown: the residual overflowed (NaN/inf)",
    8: "non-finite input: NaN/inf in b",
    9: "non-finite input: NaN/inf in x0",
    10: "non-finite input: NaN/inf in the matrix A",
    11: "Krylov breakdown: NaN/inf in the preconditioned product (a zero pivot in the "
        "factorization, or overflow)",
}


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
# Compiled kernels. Vectors are (k, m) C-contiguous blocks: for a shared
# (n, n) matrix the (k, n) block itself (the k = 3 rows go through A together,
# in one pass over its entries), for a coupled (3n, 3n) matrix
# ``b.reshape(1, 3n)``. Index arrays are passed as unsigned views (uint32 or
# uint64): numba then emits no negative-index wraparound in the inner loops
# (measured: 2x on the sparse product).

_JIT = dict(cache=True, error_model="numpy", nogil=True)


@njit(**_JIT)
def _spmv(indptr, indices, data, X, Y, R):
    """``Y = A X`` row by row of ``X``; returns ``(R, Y)`` and ``(Y, Y)`` (Frobenius).

    Every entry of ``Y`` is summed in CSR order, like scipy's ``csr_matvec``:
    the products are bitwise those of ``A @ x``.
    """
    k, m = X.shape
    ry = 0.0
    yy = 0.0
    if k == 3:
        for i in prange(m):
            y0 = 0.0
            y1 = 0.0
            y2 = 0.0
            for jj in range(indptr[i], indptr[i + 1]):
                a = data[jj]
                j = indices[jj]
                y0 += a * X[0, j]
                y1 += a * X[1, j]
                y2 += a * X[2, j]
            Y[0, i] = y0
            Y[1, i] = y1
            Y[2, i] = y2
            ry += R[0, i] * y0 + R[1, i] * y1 + R[2, i] * y2
            yy += y0 * y0 + y1 * y1 + y2 * y2
    elif k == 1:
        for i in prange(m):
            y0 = 0.0
            for jj in range(indptr[i], indptr[i + 1]):
                y0 += data[jj] * X[0, indices[jj]]
            Y[0, i] = y0
            ry += R[0, i] * y0
            yy += y0 * y0
    else:
        for i in prange(m):
            for q in range(k):
                Y[q, i] = 0.0
            for jj in range(indptr[i], indptr[i + 1]):
                a = data[jj]
                j = indices[jj]
                for q in range(k):
                    Y[q, i] += a * X[q, j]
            for q in range(k):
                ry += R[q, i] * Y[q, i]
                yy += Y[q, i] * Y[q, i]
    return ry, yy


@njit(**_JIT)
def _residual(indptr, indices, data, b, x, cmean, cfull, r):
    """``r = b - A x`` in one pass over ``A``.

    ``c`` is ``cmean[q]`` on row ``q`` (shared ``A``: ``A c = c_q rowsum``) or,
    when ``cfull`` is not empty, ``cfull`` itself. Returns ``|r|^2``,
    ``|b - A c|^2``, ``|b|^2``, ``|x|^2``, ``|A|_inf`` (largest absolute row
    sum), a code (0, or 8/9/10 for NaN/inf in ``b``/``x``/``A``) and the
    round-off bound of ``b - A c``: ``(nnz_row + 1) eps | |b| + |A| |c| |``.
    """
    k, m = b.shape
    rr = 0.0
    ref = 0.0
    bb = 0.0
    xx = 0.0
    norm_a = 0.0
    nan_a = 0.0      # entry * 0 is NaN exactly for NaN/inf entries
    nan_b = 0.0
    nan_x = 0.0
    cfloor = 0.0
    width = 0
    shared = cfull.shape[1] == 0
    if shared and k == 3:
        c0 = cmean[0]
        c1 = cmean[1]
        c2 = cmean[2]
        for i in prange(m):
            a0 = 0.0
            a1 = 0.0
            a2 = 0.0
            rs = 0.0
            ra = 0.0
            for jj in range(indptr[i], indptr[i + 1]):
                a = data[jj]
                j = indices[jj]
                a0 += a * x[0, j]
                a1 += a * x[1, j]
                a2 += a * x[2, j]
                rs += a
                ra += abs(a)
            nan_a += ra * 0.0
            norm_a = max(norm_a, ra)
            width = max(width, np.int64(indptr[i + 1] - indptr[i]))
            b0 = b[0, i]
            b1 = b[1, i]
            b2 = b[2, i]
            r0 = b0 - a0
            r1 = b1 - a1
            r2 = b2 - a2
            r[0, i] = r0
            r[1, i] = r1
            r[2, i] = r2
            rr += r0 * r0 + r1 * r1 + r2 * r2
            d0 = b0 - c0 * rs
            d1 = b1 - c1 * rs
            d2 = b2 - c2 * rs
            ref += d0 * d0 + d1 * d1 + d2 * d2
            f0 = abs(b0) + ra * abs(c0)
            f1 = abs(b1) + ra * abs(c1)
            f2 = abs(b2) + ra * abs(c2)
            cfloor += f0 * f0 + f1 * f1 + f2 * f2
            bb += b0 * b0 + b1 * b1 + b2 * b2
            nan_b += b0 * 0.0 + b1 * 0.0 + b2 * 0.0
            x0 = x[0, i]
            x1 = x[1, i]
            x2 = x[2, i]
            xx += x0 * x0 + x1 * x1 + x2 * x2
            nan_x += x0 * 0.0 + x1 * 0.0 + x2 * 0.0
    else:
        ax = np.empty(k)
        ac = np.empty(k)
        acabs = np.empty(k)
        for i in range(m):
            ax[:] = 0.0
            ac[:] = 0.0
            acabs[:] = 0.0
            rs = 0.0
            ra = 0.0
            for jj in range(indptr[i], indptr[i + 1]):
                a = data[jj]
                j = indices[jj]
                rs += a
                ra += abs(a)
                for q in range(k):
                    ax[q] += a * x[q, j]
                if not shared:
                    for q in range(k):
                        ac[q] += a * cfull[q, j]
                        acabs[q] += abs(a * cfull[q, j])
            nan_a += ra * 0.0
            if ra > norm_a:
                norm_a = ra
            width = max(width, np.int64(indptr[i + 1] - indptr[i]))
            for q in range(k):
                bq = b[q, i]
                rq = bq - ax[q]
                r[q, i] = rq
                rr += rq * rq
                d = bq - (cmean[q] * rs if shared else ac[q])
                ref += d * d
                f = abs(bq) + (ra * abs(cmean[q]) if shared else acabs[q])
                cfloor += f * f
                bb += bq * bq
                nan_b += bq * 0.0
                xq = x[q, i]
                xx += xq * xq
                nan_x += xq * 0.0
    code = 0
    if nan_b != 0.0:
        code = 8
    elif nan_x != 0.0:
        code = 9
    elif nan_a != 0.0:
        code = 10
    return rr, ref, bb, xx, norm_a, code, (width + 1) * _EPS * math.sqrt(cfloor)


@njit(**_JIT)
def _floor(indptr, indices, data, b, x):
    """``| |b| + |A| |x| |`` (Frobenius): the residual ``b - A x`` cannot be
    computed more accurately than about ``eps`` times this."""
    k, m = b.shape
    total = 0.0
    for i in range(m):
        for q in range(k):
            f = abs(b[q, i])
            for jj in range(indptr[i], indptr[i + 1]):
                f += abs(data[jj] * x[q, indices[jj]])
            total += f * f
    return math.sqrt(total)


@njit(**_JIT)
def _precondition(kind, y, z, dinv, lp, li, lx, up, ui, ux, perm_r, perm_c, w):
    """``z = M^{-1} y``: Jacobi (``kind`` 1, ``dinv = 1 / diag(A)``) or ILU
    (2; ``Pr D^{-1} A Pc ~ L U``, ``dinv = 1 / D``, ``D`` the absolute row sums)."""
    k, m = y.shape
    if kind == 1:
        for q in range(k):
            for i in range(m):
                z[q, i] = dinv[i] * y[q, i]
        return
    for q in range(k):                       # w = Pr D^{-1} y (rows equilibrated)
        for i in range(m):
            w[q, perm_r[i]] = dinv[i] * y[q, i]
    for i in range(m):                       # L w = w, forward
        d = 1.0
        for jj in range(lp[i], lp[i + 1]):
            j = li[jj]
            if j < i:
                a = lx[jj]
                for q in range(k):
                    w[q, i] -= a * w[q, j]
            elif j == i:
                d = lx[jj]
        if d != 1.0:
            for q in range(k):
                w[q, i] /= d
    for i in range(m - 1, -1, -1):           # U w = w, backward
        d = 0.0
        for jj in range(up[i], up[i + 1]):
            j = ui[jj]
            if j > i:
                a = ux[jj]
                for q in range(k):
                    w[q, i] -= a * w[q, j]
            elif j == i:
                d = ux[jj]
        for q in range(k):
            w[q, i] /= d
    for q in range(k):                       # z = Pc w
        for i in range(m):
            z[q, i] = w[q, perm_c[i]]


@njit(**_JIT)
def _bicgstab(indptr, indices, data, b, x, cmean, cfull, rtol, maxiter, window, kind,
              dinv, lp, li, lx, up, ui, ux, perm_r, perm_c):
    """BiCGStab for the (k, m) block ``b`` from ``x`` (overwritten by the result).

    Returns ``(status, detail, iterations, |r|, |b - A c|)`` (module codes).
    Unpreconditioned, the arithmetic of every vector entry is that of the
    former numpy implementation: ``s = r - v alpha``, ``x = (x + p alpha) +
    s omega``, ``r = s - t omega``, ``p = (p - v omega) beta + r``, ``alpha =
    rho / (r_hat, v)``, ``omega = (t, s) / (t, t)``, ``beta = (rho' / rho)
    (alpha / omega)``; only the summation order of the inner products differs.
    Every vector update is one pass fused with the inner products it feeds.
    """
    k, m = b.shape
    n = k * m
    r = np.empty_like(b)
    rr, ref2, bb, xx, norm_a, bad, cfloor = _residual(indptr, indices, data, b, x, cmean,
                                                      cfull, r)
    if bad != 0:
        return _BREAKDOWN, bad, 0, math.nan, math.nan
    ref = math.sqrt(ref2)
    rnorm = math.sqrt(rr)
    if ref <= cfloor:           # A c = b up to round-off: c is the solution
        if cfull.shape[1] == 0:
            for q in range(k):
                x[q, :] = cmean[q]
        else:
            x[:, :] = cfull
        return _CONVERGED, 0, 0, 0.0, 0.0
    if not (math.isfinite(ref) and math.isfinite(rnorm)):
        return _BREAKDOWN, 7, 0, rnorm, ref
    tol = rtol * ref
    if rnorm <= tol:            # r = b - A x0 is the true residual
        return _CONVERGED, 0, 0, rnorm, ref
    bnorm = math.sqrt(bb)
    rmax = rnorm
    r_hat = r.copy()
    p = r.copy()
    v = np.empty_like(b)
    s = np.empty_like(b)
    t = np.empty_like(b)
    if kind == 0:
        ph = p
        sh = s
        w = np.empty((k, 0))
    else:
        ph = np.empty_like(b)
        sh = np.empty_like(b)
        w = np.empty_like(b)
    xf = x.reshape(n)
    rf = r.reshape(n)
    rhf = r_hat.reshape(n)
    pf = p.reshape(n)
    vf = v.reshape(n)
    sf = s.reshape(n)
    tf = t.reshape(n)
    phf = ph.reshape(n)
    shf = sh.reshape(n)
    rho = rr
    rmin = rnorm
    it_min = 0
    xx_min = xx                 # |x|^2 at the smallest residual
    last_true = math.inf        # true residual at the last residual replacement
    check = False               # verify the true residual before accepting
    it = 0
    while it < maxiter or check:
        if check:               # accept, restart from the true residual, or stagnate
            check = False
            tr2, ref2, bb, xx, norm_a, bad, _ = _residual(indptr, indices, data, b, x, cmean,
                                                          cfull, r)
            true = math.sqrt(tr2)
            if true <= tol:
                return _CONVERGED, 0, it, true, ref
            if not math.isfinite(true):
                return _BREAKDOWN, 7, it, true, ref
            if true >= 0.5 * last_true:
                return _STAGNATED, 2, it, true, ref
            last_true = true
            r_hat[:, :] = r
            p[:, :] = r
            rho = tr2
            rnorm = true
            rmin = true
            it_min = it
            xx_min = xx
            if it >= maxiter:
                break
        it += 1
        if kind != 0:
            _precondition(kind, p, ph, dinv, lp, li, lx, up, ui, ux, perm_r, perm_c, w)
        rv, _ = _spmv(indptr, indices, data, ph, v, r_hat)
        if not math.isfinite(rv):
            return _BREAKDOWN, 11 if kind != 0 else 7, it, rnorm, ref
        if rv == 0.0:
            return _BREAKDOWN, 2, it, rnorm, ref
        alpha = rho / rv
        if not math.isfinite(alpha):
            return _BREAKDOWN, 5, it, rnorm, ref
        ss = 0.0
        for i in prange(n):                  # s = r - alpha v
            si = rf[i] - vf[i] * alpha
            sf[i] = si
            ss += si * si
        snorm = math.sqrt(ss)
        if not math.isfinite(snorm):
            return _BREAKDOWN, 7, it, snorm, ref
        if snorm <= tol:                    # half-step exit: still one iteration
            xx = 0.0
            for i in prange(n):
                xi = xf[i] + phf[i] * alpha
                xf[i] = xi
                xx += xi * xi
            rmax = max(rmax, snorm)
            if tol >= _TRUST * _EPS * (norm_a * math.sqrt(xx) + bnorm + rmax):
                return _CONVERGED, 0, it, snorm, ref
            check = True
            continue
        if kind != 0:
            _precondition(kind, s, sh, dinv, lp, li, lx, up, ui, ux, perm_r, perm_c, w)
        ts, tt = _spmv(indptr, indices, data, sh, t, s)
        if not (math.isfinite(ts) and math.isfinite(tt)):
            return _BREAKDOWN, 11 if kind != 0 else 7, it, snorm, ref
        if tt == 0.0:
            return _BREAKDOWN, 4, it, snorm, ref
        if ts == 0.0:
            return _BREAKDOWN, 3, it, snorm, ref
        omega = ts / tt
        rr = 0.0
        rho_new = 0.0
        xx = 0.0
        for i in prange(n):                  # x += alpha p + omega s; r = s - omega t
            xi = (xf[i] + phf[i] * alpha) + shf[i] * omega
            xf[i] = xi
            xx += xi * xi
            ri = sf[i] - tf[i] * omega
            rf[i] = ri
            rr += ri * ri
            rho_new += rhf[i] * ri
        rnorm = math.sqrt(rr)
        if not math.isfinite(rnorm):
            return _BREAKDOWN, 7, it, rnorm, ref
        rmax = max(rmax, rnorm)
        if rnorm <= tol:
            if tol >= _TRUST * _EPS * (norm_a * math.sqrt(xx) + bnorm + rmax):
                return _CONVERGED, 0, it, rnorm, ref
            check = True
            continue
        if rnorm < rmin:
            rmin = rnorm
            it_min = it
            xx_min = xx
        elif it - it_min >= window:     # no progress: at the round-off floor?
            if xx <= 4.0 * xx_min and \
                    rmin <= _TRUST * _EPS * _floor(indptr, indices, data, b, x):
                return _STAGNATED, 1, it, rnorm, ref
            it_min = it                 # no: look again after another window
        if rho_new == 0.0:
            return _BREAKDOWN, 1, it, rnorm, ref
        beta = (rho_new / rho) * (alpha / omega)
        if not math.isfinite(beta):
            return _BREAKDOWN, 6, it, rnorm, ref
        rho = rho_new
        for i in prange(n):                  # p = r + beta (p - omega v)
            pf[i] = (pf[i] - vf[i] * omega) * beta + rf[i]
    return _MAXITER, 0, it, rnorm, ref


# ---------------------------------------------------------------------------
# Python side: layouts, factorizations, reports

_NO_INT = np.zeros(1, dtype=np.uint32)
_NO_FLOAT = np.zeros(0)


def _unsigned(a):
    """A view (or copy) of a non-negative index array as uint32/uint64."""
    a = np.asarray(a)
    if a.dtype in (np.int32, np.uint32):
        return np.ascontiguousarray(a).view(np.uint32)
    return np.ascontiguousarray(a, dtype=np.int64).view(np.uint64)


def _csr(A):
    """``(indptr, indices, data)`` of ``A`` as CSR, the index arrays unsigned views."""
    if not (sp.issparse(A) and A.format == "csr"):
        if not sp.issparse(A):
            A = np.asarray(A, dtype=float)
            if A.ndim != 2:
                raise ValueError(f"A must be a 2-D matrix, got shape {A.shape}")
        A = sp.csr_matrix(A)
    return _unsigned(A.indptr), _unsigned(A.indices), np.ascontiguousarray(A.data, np.float64)


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
    with np.errstate(all="ignore"):
        # x.mean(axis=1) without its Python wrapper (the same sum and division)
        cmean = np.add.reduce(x, axis=1) / n if n else np.zeros(k)
    if not coupled:
        return b, x, cmean, np.empty((k, 0)), lambda z: z
    cfull = np.repeat(cmean, n).reshape(1, k * n)
    return (b.reshape(1, k * n), x.reshape(1, k * n), cmean, cfull,
            lambda z: z.reshape(k, n))


def _factorize(A, ilu, drop_tol=1e-4, fill_factor=10.0):
    """SuperLU ``splu``/``spilu`` of ``A``: ``(lu, None)`` or ``(None, detail)``."""
    import scipy.sparse.linalg as spla  # on first use (import cost at start-up)

    what = "ILU" if ilu else "LU"
    try:
        with np.errstate(all="ignore"):
            Ac = sp.csc_matrix(A, dtype=float)
            lu = (spla.spilu(Ac, drop_tol=drop_tol, fill_factor=fill_factor) if ilu
                  else spla.splu(Ac))
    except RuntimeError as err:      # "Factor is exactly singular"
        return None, f"{what} factorization failed: {str(err).rstrip('.').lower()}"
    return lu, None


def _ilu_arrays(lu):
    """CSR arrays of the ILU factors and the permutations, for the kernel."""
    if lu is None:
        return (_NO_INT, _NO_INT, _NO_FLOAT, _NO_INT, _NO_INT, _NO_FLOAT, _NO_INT, _NO_INT)
    L, U = lu.L.tocsr(), lu.U.tocsr()
    return (_unsigned(L.indptr), _unsigned(L.indices), np.ascontiguousarray(L.data, float),
            _unsigned(U.indptr), _unsigned(U.indices), np.ascontiguousarray(U.data, float),
            _unsigned(lu.perm_r), _unsigned(lu.perm_c))


def _failed(method, status, detail, residual=math.nan, iterations=0):
    return SolveInfo(int(iterations), float(residual), False, status, method, detail)


def solve(A, b, x0=None, *, method="bicgstab", rtol=1e-9, maxiter=1000,
          stagnation_window=50, ilu_drop_tol=1e-4, ilu_fill_factor=10.0, overwrite_x0=False,
          threads=1):
    """Solve ``A x = b`` for a (k, n) block ``b`` from ``x0``; reports failures in ``info``.

    Parameters
    ----------
    A : (n, n) or (k n, k n) scipy sparse matrix (or dense array)
        Shared by the k rows of ``b``, or acting on ``b.ravel()``.
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
        blocks, :func:`ddfv.kernels.for_threads`), at most
        ``numba.config.NUMBA_NUM_THREADS``. With more than one the inner
        products are summed in another order: the iterates agree to
        round-off, not bitwise.

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
    if method not in METHODS:
        raise ValueError(f"unknown solver method {method!r}; choose one of "
                         f"{', '.join(METHODS)}")
    check_threads(threads)
    b, x, cmean, cfull, to_block = _blocks(A, b, x0, overwrite_x0)
    csr = _csr(A)
    with np.errstate(all="ignore"):
        if method == "direct":
            x, info = _direct(A, csr, b, x, cmean, cfull, rtol)
            return to_block(x), info
        kind, dinv, lu = 0, _NO_FLOAT, None
        if method == "jacobi-bicgstab":
            kind = 1
            d = sp.csr_matrix(A).diagonal().astype(float)
            dinv = np.where(d != 0.0, 1.0 / np.where(d != 0.0, d, 1.0), 1.0)
        elif method == "ilu-bicgstab":
            if np.isfinite(csr[2]).all() and np.isfinite(b).all() and np.isfinite(x).all():
                kind = 2
                A = sp.csr_matrix(A, dtype=float)
                rows = np.asarray(abs(A).sum(axis=1)).ravel()
                dinv = np.where(rows > 0.0, 1.0 / np.where(rows > 0.0, rows, 1.0), 1.0)
                lu, detail = _factorize(sp.diags(dinv) @ A, True, ilu_drop_tol,
                                        ilu_fill_factor)
                if lu is None:       # an exactly zero pivot: try the rows unscaled
                    dinv = np.ones(A.shape[0])
                    lu, detail = _factorize(A, True, ilu_drop_tol, ilu_fill_factor)
                if lu is None:
                    return to_block(x), _failed(method, "breakdown", detail)
            # else: kind 0, the kernel reports the non-finite input
        code, dcode, it, rnorm, ref = for_threads(_bicgstab, threads, _spmv=_spmv,
                                                   _residual=_residual)(
            *csr, b, x, cmean, cfull, float(rtol), int(maxiter), int(stagnation_window),
            kind, dinv, *_ilu_arrays(lu))
        residual = (rnorm / ref if ref > 0.0 else
                    0.0 if rnorm == 0.0 else math.nan if math.isnan(ref) else math.inf)
    detail = ""
    if code == _MAXITER:
        detail = f"iteration limit {maxiter} reached"
    elif code == _STAGNATED:
        detail = (f"stagnation: no new residual minimum in the last {stagnation_window} "
                  "iterations, at the round-off floor" if dcode == 1 else
                  "stagnation: the true residual stays above the tolerance at the "
                  "round-off floor")
    elif code == _BREAKDOWN:
        detail = _DETAIL[dcode]
    return to_block(x), SolveInfo(int(it), float(residual), code == _CONVERGED,
                                  _STATUS[code], method, detail)


def _direct(A, csr, b, x0, cmean, cfull, rtol):
    """LU solve in the (k, m) layout, iterative refinement, residual check."""
    method = "direct"
    r = np.empty_like(b)
    _, ref2, _, _, _, bad, cfloor = _residual(*csr, b, x0, cmean, cfull, r)
    if bad:
        return x0, _failed(method, "breakdown", _DETAIL[bad])
    ref = math.sqrt(ref2)
    if ref <= cfloor:                # A c = b up to round-off: c is the solution
        x = np.empty_like(b)
        x[...] = cmean[:, None] if cfull.shape[1] == 0 else cfull
        return x, SolveInfo(0, 0.0, True, "converged", method)
    lu, detail = _factorize(A, False)
    if lu is None:
        return x0, _failed(method, "breakdown", detail)

    def lu_solve(rhs):               # the k rows at once
        return np.ascontiguousarray(lu.solve(np.ascontiguousarray(rhs.T)).T)

    x = lu_solve(b)
    best = math.inf
    for step in range(_REFINEMENTS + 1):
        rr, *_ = _residual(*csr, b, x, cmean, cfull, r)
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


def bicgstab(A, b, x0, rtol=1e-10, maxiter=1000):
    """The paper's BiCGStab, the former entry point: ``solve(A, b, x0,
    method="bicgstab", rtol=rtol, maxiter=maxiter)`` (does not raise)."""
    return solve(A, b, x0, method="bicgstab", rtol=rtol, maxiter=maxiter)


def apply_block(A, X, out=None):
    """``A`` applied to the (k, n) block ``X`` (into ``out`` if given).

    ``A`` is (n, n), applied to every row, or (k n, k n), applied to
    ``X.ravel()``: one compiled pass over the entries of ``A`` for all rows,
    each entry bitwise that of scipy's ``A @ x``.
    """
    X = np.ascontiguousarray(X, dtype=float)
    if X.ndim != 2:
        raise ValueError(f"X must be a (k, n) block, got shape {X.shape}")
    shape = (1, X.size) if _coupled(A, X.shape) else X.shape
    into = (out is not None and out.shape == X.shape and out.dtype == np.float64
            and out.flags.c_contiguous and not np.shares_memory(out, X))
    Y = out if into else np.empty_like(X)
    Yi = Y.reshape(shape)
    _spmv(*_csr(A), X.reshape(shape), Yi, Yi)
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
        ``scipy.sparse.linalg.spilu`` parameters of ``"ilu-bicgstab"``.
    threads : int
        Threads of the BiCGStab products and vector updates (see :func:`solve`).
    """

    method: str = "bicgstab"
    rtol: float = 1e-9
    maxiter: int = 1000
    stagnation_window: int = 50
    ilu_drop_tol: float = 1e-4
    ilu_fill_factor: float = 10.0
    threads: int = 1

    #: ``solver(A, b, x0, overwrite_x0=True)`` iterates in ``x0`` (no copy), see :func:`solve`
    can_overwrite_x0 = True

    def __post_init__(self):
        if self.method not in METHODS:
            raise ValueError(f"unknown solver method {self.method!r}; choose one of "
                             f"{', '.join(METHODS)}")
        if not (isinstance(self.rtol, (int, float)) and 0 < self.rtol < 1):
            raise ValueError(f"rtol must lie in (0, 1), got {self.rtol!r}")
        for name in ("maxiter", "stagnation_window"):
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
        x, info = solve(A, b, x0, method=self.method, rtol=self.rtol, maxiter=self.maxiter,
                        stagnation_window=self.stagnation_window,
                        ilu_drop_tol=self.ilu_drop_tol,
                        ilu_fill_factor=self.ilu_fill_factor, overwrite_x0=overwrite_x0,
                        threads=self.threads)
        if not info.converged:
            raise SolverFailure(info, self.rtol, self.maxiter)
        return x, info
