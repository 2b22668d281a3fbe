"""BiCGStab (van der Vorst 1992, the paper's [10]) for a block of right-hand sides.

The three coordinate systems of one time step share their matrix, so they
are solved as ONE linear system of size ``3 n``: the unknown is a (3, n)
block (one row per coordinate), inner products and norms are Frobenius, and
every iteration costs two sparse products with the whole block.

Iteration count: one iteration is one pass of the BiCGStab loop (two
products with ``A``); an exit in its middle (``|s|`` already small) counts
as a whole iteration. A solve that is converged at ``x0`` counts 0.
Stopping test: ``|b - A x| <= rtol |b|`` on the recurrence residual.
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SolveInfo:
    """Outcome of one solve.

    Attributes
    ----------
    iterations : int
        BiCGStab iterations (see module docstring).
    residual : float
        Final relative residual ``|r| / |b|``.
    converged : bool
    """

    iterations: int
    residual: float
    converged: bool


def bicgstab(A, b, x0, rtol=1e-10, maxiter=1000):
    """Solve ``A x = b`` for a (k, n) block ``b`` (k right-hand sides), from ``x0``.

    Parameters
    ----------
    A : (n, n) sparse matrix or anything supporting ``A @ x`` for (n,) ``x``
    b, x0 : (k, n) float arrays
    rtol : float
        Relative tolerance on the residual, ``|r| <= rtol |b|``.
    maxiter : int

    Returns
    -------
    x : (k, n) float array
    info : SolveInfo
        ``converged`` is False after ``maxiter`` iterations or a breakdown
        (``rho = 0`` or ``omega = 0``); ``x`` is then the last iterate.
    """
    bnorm = _norm(b)
    if bnorm == 0.0:
        return np.zeros_like(b), SolveInfo(0, 0.0, True)
    tol = rtol * bnorm
    x = np.array(x0, dtype=float, copy=True)
    r = apply_block(A, x)
    np.subtract(b, r, out=r)
    rnorm = _norm(r)
    if rnorm <= tol:
        return x, SolveInfo(0, rnorm / bnorm, True)
    # every vector lives in one buffer, updated in place
    r_hat, p, v, s, t, work = (np.empty_like(r) for _ in range(6))
    r_hat[...] = p[...] = r
    rho = _dot(r_hat, r)
    for it in range(1, maxiter + 1):
        apply_block(A, p, out=v)
        alpha = rho / _dot(r_hat, v)
        np.subtract(r, np.multiply(v, alpha, out=work), out=s)   # s = r - alpha v
        x += np.multiply(p, alpha, out=work)
        snorm = _norm(s)
        if snorm <= tol:  # half-step exit: still one iteration
            return x, SolveInfo(it, snorm / bnorm, True)
        apply_block(A, s, out=t)
        tt = _dot(t, t)
        omega = _dot(t, s) / tt if tt > 0.0 else 0.0
        if omega == 0.0:
            return x, SolveInfo(it, snorm / bnorm, False)
        x += np.multiply(s, omega, out=work)
        np.subtract(s, np.multiply(t, omega, out=work), out=r)   # r = s - omega t
        rnorm = _norm(r)
        if rnorm <= tol:
            return x, SolveInfo(it, rnorm / bnorm, True)
        rho_new = _dot(r_hat, r)
        if rho_new == 0.0:
            return x, SolveInfo(it, rnorm / bnorm, False)
        beta = (rho_new / rho) * (alpha / omega)
        rho = rho_new
        p -= np.multiply(v, omega, out=work)     # p = r + beta (p - omega v)
        p *= beta
        p += r
    return x, SolveInfo(maxiter, rnorm / bnorm, False)


def apply_block(A, X, out=None):
    """``A`` applied to every row of a (k, n) block ``X`` (into ``out`` if given).

    In scipy, k products with vectors are faster than one product with an
    (n, k) block (measured: 0.9 ms against 1.3 ms at level 5).
    """
    if out is None:
        out = np.empty_like(X)
    for k, x in enumerate(X):
        out[k] = A @ x
    return out


def _dot(x, y):
    return float(np.vdot(x, y))


def _norm(x):
    return float(np.sqrt(np.vdot(x, x)))
