"""The compiled kernels of the shared solver: BiCGStab (van der Vorst 1992, the
paper's [10]) on a block of right-hand sides, its residuals and preconditioners,
the block product, and the status and breakdown codes they return. Called
through :func:`mcfbench.running.solver.solve`."""

import math

import numpy as np
from numba import njit, prange

_EPS = float(np.finfo(float).eps)
_TRUST = 1e3             # trust the recurrence residual when tol >= _TRUST * round-off floor


# status codes of the compiled kernel
CONVERGED, MAXITER, BREAKDOWN, STAGNATED = 0, 1, 2, 3
STATUS_NAMES = {CONVERGED: "converged", MAXITER: "max_iterations", BREAKDOWN: "breakdown",
                STAGNATED: "stagnated"}
# what broke down (detail codes of the kernel)
BREAKDOWN_DETAILS = {
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


_JIT = dict(cache=True, error_model="numpy", nogil=True)


@njit(**_JIT, inline="always")
def _row3(indptr, indices, data, X, i):
    """Row ``i`` of ``A`` times the three rows of ``X``, summed in CSR order, with the
    row's sum and absolute sum: ``(A X_0)_i, (A X_1)_i, (A X_2)_i, sum_j a_ij,
    sum_j |a_ij|`` (:func:`spmv` and :func:`residual`; inlined, the sums a caller
    does not use are not computed)."""
    y0 = 0.0
    y1 = 0.0
    y2 = 0.0
    rs = 0.0
    ra = 0.0
    for jj in range(indptr[i], indptr[i + 1]):
        a = data[jj]
        j = indices[jj]
        y0 += a * X[0, j]
        y1 += a * X[1, j]
        y2 += a * X[2, j]
        rs += a
        ra += abs(a)
    return y0, y1, y2, rs, ra


@njit(**_JIT, inline="always")
def _row4(indptr, indices, data, X, i):
    """:func:`_row3` for four rows of ``X`` (kll's block solve, ``baselines/kll.py``):
    ``(A X_0)_i, ..., (A X_3)_i, sum_j a_ij, sum_j |a_ij|``, the sums in registers
    (stored after every entry they were a chain through memory, 2.6 x slower)."""
    y0 = 0.0
    y1 = 0.0
    y2 = 0.0
    y3 = 0.0
    rs = 0.0
    ra = 0.0
    for jj in range(indptr[i], indptr[i + 1]):
        a = data[jj]
        j = indices[jj]
        y0 += a * X[0, j]
        y1 += a * X[1, j]
        y2 += a * X[2, j]
        y3 += a * X[3, j]
        rs += a
        ra += abs(a)
    return y0, y1, y2, y3, rs, ra


@njit(**_JIT)
def spmv(indptr, indices, data, X, Y, R):
    """``Y = A X`` row by row of ``X``; returns ``(R, Y)`` and ``(Y, Y)`` (Frobenius).

    Every entry of ``Y`` is summed in CSR order, like scipy's ``csr_matvec``:
    the products are bitwise those of ``A @ x``.
    """
    k, m = X.shape
    ry = 0.0
    yy = 0.0
    if k == 3:
        for i in prange(m):
            y0, y1, y2, _, _ = _row3(indptr, indices, data, X, i)
            Y[0, i] = y0
            Y[1, i] = y1
            Y[2, i] = y2
            ry += R[0, i] * y0 + R[1, i] * y1 + R[2, i] * y2
            yy += y0 * y0 + y1 * y1 + y2 * y2
    elif k == 4:
        for i in prange(m):
            y0, y1, y2, y3, _, _ = _row4(indptr, indices, data, X, i)
            Y[0, i] = y0
            Y[1, i] = y1
            Y[2, i] = y2
            Y[3, i] = y3
            for q in range(4):       # as the general path (one reduction statement each)
                ry += R[q, i] * Y[q, i]
                yy += Y[q, i] * Y[q, i]
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
def _shared_floor(indptr, indices, data, b, c):
    """``(nnz_row + 1) eps | |b| + |A| |c| |`` for a shared ``A`` and a (3, m) ``b``,
    ``c`` the three per-row constants: the round-off bound of :func:`residual`,
    summed in its order (rows in turn, then the three rows of ``b``)."""
    m = b.shape[1]
    c0 = abs(c[0])
    c1 = abs(c[1])
    c2 = abs(c[2])
    total = 0.0
    width = 0
    for i in range(m):
        ra = 0.0
        for jj in range(indptr[i], indptr[i + 1]):
            ra += abs(data[jj])
        width = max(width, np.int64(indptr[i + 1] - indptr[i]))
        f0 = abs(b[0, i]) + ra * c0
        f1 = abs(b[1, i]) + ra * c1
        f2 = abs(b[2, i]) + ra * c2
        total += f0 * f0 + f1 * f1 + f2 * f2
    return (width + 1) * _EPS * math.sqrt(total)


@njit(**_JIT)
def residual(indptr, indices, data, b, x, cmean, cfull, r):
    """``r = b - A x`` in one pass over ``A``.

    ``c`` is ``cmean[q]`` on row ``q`` (shared ``A``: ``A c = c_q rowsum``) or,
    when ``cfull`` is not empty, ``cfull`` itself. Returns ``|r|^2``,
    ``|b - A c|^2``, ``|b|^2``, ``|x|^2``, ``|A|_inf`` (largest absolute row
    sum), a code (0, or 8/9/10 for NaN/inf in ``b``/``x``/``A``) and the
    round-off bound of ``b - A c``: ``(nnz_row + 1) eps | |b| + |A| |c| |``.

    A shared ``A`` with three rows of ``b`` (the surface schemes' systems)
    takes the pass of the fewest sums: a non-finite entry shows in ``|b|^2``,
    ``|x|^2`` or the sum of the squared absolute row sums, and only then is
    the array checked entry by entry (those sums may also overflow); the
    round-off bound (only compared with ``|b - A c|``, to find ``c`` the
    solution) is computed in a second pass (:func:`_shared_floor`) only when
    ``|b - A c|`` is below twice its upper bound by Minkowski's inequality,
    ``(nnz_row + 1) eps (|b| + |rowsum |A|| |c|)``; otherwise that upper bound
    is returned. The comparison has the same outcome as with the bound
    itself; the pass costs 0.415 ms against 0.49 ms with the four sums
    (level-5 sphere, DDFV, min of 300 calls).
    """
    k, m = b.shape
    rr = 0.0
    ref = 0.0
    bb = 0.0
    xx = 0.0
    norm_a = 0.0
    width = 0
    shared = cfull.shape[1] == 0
    if shared and k == 3:
        c0 = cmean[0]
        c1 = cmean[1]
        c2 = cmean[2]
        ra2 = 0.0
        for i in prange(m):
            a0, a1, a2, rs, ra = _row3(indptr, indices, data, x, i)
            ra2 += ra * ra
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
            bb += b0 * b0 + b1 * b1 + b2 * b2
            x0 = x[0, i]
            x1 = x[1, i]
            x2 = x[2, i]
            xx += x0 * x0 + x1 * x1 + x2 * x2
        code = 0
        if not math.isfinite(bb) and not np.isfinite(b).all():
            code = 8
        elif not math.isfinite(xx) and not np.isfinite(x).all():
            code = 9
        elif not math.isfinite(ra2) and not np.isfinite(data[indptr[0]:indptr[m]]).all():
            code = 10
        bound = (width + 1) * _EPS * (math.sqrt(bb) + math.sqrt(ra2) *
                                      math.sqrt(c0 * c0 + c1 * c1 + c2 * c2))
        if code == 0 and not ref > 4.0 * bound * bound:     # |b - A c| <= 2 bound
            bound = _shared_floor(indptr, indices, data, b, cmean)
        return rr, ref, bb, xx, norm_a, code, bound
    nan_a = 0.0      # entry * 0 is NaN exactly for NaN/inf entries
    nan_b = 0.0
    nan_x = 0.0
    cfloor = 0.0
    ax = np.empty(k)
    ac = np.empty(k)
    acabs = np.empty(k)
    for i in range(m):
        if shared and k == 4:    # the general path's sums, in registers
            a0, a1, a2, a3, rs, ra = _row4(indptr, indices, data, x, i)
            ax[0] = a0
            ax[1] = a1
            ax[2] = a2
            ax[3] = a3
        else:
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
def roundoff_floor(indptr, indices, data, b, x):
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


@njit(**_JIT, inline="always")
def _substitute(ptr, idx, val, w, q, i, lower):
    """Row ``i`` of a triangular factor (CSR) against row ``q`` of ``w``: the sum and the
    diagonal entry of :func:`_substitute3`, for a block of other than three rows."""
    d = 1.0 if lower else 0.0
    acc = w[q, i]
    for jj in range(ptr[i], ptr[i + 1]):
        j = idx[jj]
        if (j < i) if lower else (j > i):
            acc -= val[jj] * w[q, j]
        elif j == i:
            d = val[jj]
    return acc, d


@njit(**_JIT, inline="always")
def _substitute3(ptr, idx, val, w, i, lower):
    """Row ``i`` of a triangular factor (CSR) against the three rows of ``w``: ``w[q, i]
    - sum_j a_ij w[q, j]`` over its entries strictly below (``lower``) or above the
    diagonal, subtracted in CSR order, and the diagonal entry (when absent 1 in ``L``,
    0 in ``U``: a breakdown; of :func:`precondition`, inlined). The three sums are kept
    in registers: written to ``w`` after every entry they were a chain through memory,
    three times slower (anisotropic sphere level 4, 6.1 M entries in ``L + U``: 31-39
    ms against 11-13 ms a call)."""
    w0 = w[0, i]
    w1 = w[1, i]
    w2 = w[2, i]
    d = 1.0 if lower else 0.0
    for jj in range(ptr[i], ptr[i + 1]):
        j = idx[jj]
        if (j < i) if lower else (j > i):
            a = val[jj]
            w0 -= a * w[0, j]
            w1 -= a * w[1, j]
            w2 -= a * w[2, j]
        elif j == i:
            d = val[jj]
    return w0, w1, w2, d


@njit(**_JIT)
def precondition(kind, y, z, dinv, lp, li, lx, up, ui, ux, perm_r, perm_c, w):
    """``z = M^{-1} y``: Jacobi (``kind`` 1, ``dinv = 1 / diag(A)``) or ILU
    (2; ``Pr D^{-1} A Pc ~ L U``, ``dinv = 1 / D``, ``D`` the absolute row sums).
    The triangular solves take the k rows of ``y`` in one pass over the factors, every
    entry's sum in CSR order (the same arithmetic for every k). An ILU factor smaller
    than ``y``'s rows, (n, n) for (k, c n), is applied to each of their c n-blocks (a
    coupled system's isotropic part,
    :func:`mcfbench.running.factorizations.isotropic_ilu_factor`): one pass over the
    factor for all of them."""
    k, m = y.shape
    if kind == 1:
        for q in range(k):
            for i in range(m):
                z[q, i] = dinv[i] * y[q, i]
        return
    n = perm_r.shape[0]
    if n != m:
        y = y.reshape(k * (m // n), n)
        z = z.reshape(k * (m // n), n)
        w = w.reshape(k * (m // n), n)
        k, m = y.shape
    for q in range(k):                       # w = Pr D^{-1} y (rows equilibrated)
        for i in range(m):
            w[q, perm_r[i]] = dinv[i] * y[q, i]
    for i in range(m):                       # L w = w, forward
        if k == 3:
            w0, w1, w2, d = _substitute3(lp, li, lx, w, i, True)
            w[0, i] = w0 / d if d != 1.0 else w0
            w[1, i] = w1 / d if d != 1.0 else w1
            w[2, i] = w2 / d if d != 1.0 else w2
            continue
        for q in range(k):
            acc, d = _substitute(lp, li, lx, w, q, i, True)
            w[q, i] = acc / d if d != 1.0 else acc
    for i in range(m - 1, -1, -1):           # U w = w, backward
        if k == 3:
            w0, w1, w2, d = _substitute3(up, ui, ux, w, i, False)
            w[0, i] = w0 / d
            w[1, i] = w1 / d
            w[2, i] = w2 / d
            continue
        for q in range(k):
            acc, d = _substitute(up, ui, ux, w, q, i, False)
            w[q, i] = acc / d
    for q in range(k):                       # z = Pc w
        for i in range(m):
            z[q, i] = w[q, perm_c[i]]


@njit(**_JIT)
def bicgstab_kernel(indptr, indices, data, b, x, cmean, cfull, rtol, maxiter, window, kind,
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
    rr, ref2, bb, xx, norm_a, bad, cfloor = residual(indptr, indices, data, b, x, cmean,
                                                      cfull, r)
    if bad != 0:
        return BREAKDOWN, bad, 0, math.nan, math.nan
    ref = math.sqrt(ref2)
    rnorm = math.sqrt(rr)
    if ref <= cfloor:           # A c = b up to round-off: c is the solution
        if cfull.shape[1] == 0:
            for q in range(k):
                x[q, :] = cmean[q]
        else:
            x[:, :] = cfull
        return CONVERGED, 0, 0, 0.0, 0.0
    if not (math.isfinite(ref) and math.isfinite(rnorm)):
        return BREAKDOWN, 7, 0, rnorm, ref
    tol = rtol * ref
    if rnorm <= tol:            # r = b - A x0 is the true residual
        return CONVERGED, 0, 0, rnorm, ref
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
            tr2, ref2, bb, xx, norm_a, bad, _ = residual(indptr, indices, data, b, x, cmean,
                                                          cfull, r)
            true = math.sqrt(tr2)
            if true <= tol:
                return CONVERGED, 0, it, true, ref
            if not math.isfinite(true):
                return BREAKDOWN, 7, it, true, ref
            if true >= 0.5 * last_true:
                return STAGNATED, 2, it, true, ref
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
            precondition(kind, p, ph, dinv, lp, li, lx, up, ui, ux, perm_r, perm_c, w)
        rv, _ = spmv(indptr, indices, data, ph, v, r_hat)
        if not math.isfinite(rv):
            return BREAKDOWN, 11 if kind != 0 else 7, it, rnorm, ref
        if rv == 0.0:
            return BREAKDOWN, 2, it, rnorm, ref
        alpha = rho / rv
        if not math.isfinite(alpha):
            return BREAKDOWN, 5, it, rnorm, ref
        ss = 0.0
        for i in prange(n):                  # s = r - alpha v
            si = rf[i] - vf[i] * alpha
            sf[i] = si
            ss += si * si
        snorm = math.sqrt(ss)
        if not math.isfinite(snorm):
            return BREAKDOWN, 7, it, snorm, ref
        if snorm <= tol:                    # half-step exit: still one iteration
            xx = 0.0
            for i in prange(n):
                xi = xf[i] + phf[i] * alpha
                xf[i] = xi
                xx += xi * xi
            rmax = max(rmax, snorm)
            if tol >= _TRUST * _EPS * (norm_a * math.sqrt(xx) + bnorm + rmax):
                return CONVERGED, 0, it, snorm, ref
            check = True
            continue
        if kind != 0:
            precondition(kind, s, sh, dinv, lp, li, lx, up, ui, ux, perm_r, perm_c, w)
        ts, tt = spmv(indptr, indices, data, sh, t, s)
        if not (math.isfinite(ts) and math.isfinite(tt)):
            return BREAKDOWN, 11 if kind != 0 else 7, it, snorm, ref
        if tt == 0.0:
            return BREAKDOWN, 4, it, snorm, ref
        if ts == 0.0:
            return BREAKDOWN, 3, it, snorm, ref
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
            return BREAKDOWN, 7, it, rnorm, ref
        rmax = max(rmax, rnorm)
        if rnorm <= tol:
            if tol >= _TRUST * _EPS * (norm_a * math.sqrt(xx) + bnorm + rmax):
                return CONVERGED, 0, it, rnorm, ref
            check = True
            continue
        if rnorm < rmin:
            rmin = rnorm
            it_min = it
            xx_min = xx
        elif it - it_min >= window:     # no progress: at the round-off floor?
            if xx <= 4.0 * xx_min and \
                    rmin <= _TRUST * _EPS * roundoff_floor(indptr, indices, data, b, x):
                return STAGNATED, 1, it, rnorm, ref
            it_min = it                 # no: look again after another window
        if rho_new == 0.0:
            return BREAKDOWN, 1, it, rnorm, ref
        beta = (rho_new / rho) * (alpha / omega)
        if not math.isfinite(beta):
            return BREAKDOWN, 6, it, rnorm, ref
        rho = rho_new
        for i in prange(n):                  # p = r + beta (p - omega v)
            pf[i] = (pf[i] - vf[i] * omega) * beta + rf[i]
    return MAXITER, 0, it, rnorm, ref
