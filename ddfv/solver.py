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
    r = b - apply_block(A, x)
    rnorm = _norm(r)
    if rnorm <= tol:
        return x, SolveInfo(0, rnorm / bnorm, True)
    r_hat = r.copy()
    p = np.zeros_like(r)
    v = np.zeros_like(r)
    rho = alpha = omega = 1.0
    for it in range(1, maxiter + 1):
        rho_new = _dot(r_hat, r)
        if rho_new == 0.0 or omega == 0.0:
            return x, SolveInfo(it - 1, rnorm / bnorm, False)
        beta = (rho_new / rho) * (alpha / omega)
        p = r + beta * (p - omega * v)
        v = apply_block(A, p)
        alpha = rho_new / _dot(r_hat, v)
        s = r - alpha * v
        snorm = _norm(s)
        if snorm <= tol:  # half-step exit: still one iteration
            x += alpha * p
            return x, SolveInfo(it, snorm / bnorm, True)
        t = apply_block(A, s)
        omega = _dot(t, s) / _dot(t, t)
        x += alpha * p + omega * s
        r = s - omega * t
        rnorm = _norm(r)
        if rnorm <= tol:
            return x, SolveInfo(it, rnorm / bnorm, True)
        rho = rho_new
    return x, SolveInfo(maxiter, rnorm / bnorm, False)


def apply_block(A, X):
    """``A`` applied to every row of a (k, n) block ``X``.

    In scipy, k products with vectors are faster than one product with an
    (n, k) block (measured: 0.9 ms against 1.3 ms at level 5).
    """
    out = np.empty_like(X)
    for k, x in enumerate(X):
        out[k] = A @ x
    return out


def _dot(x, y):
    return float(np.vdot(x, y))


def _norm(x):
    return float(np.sqrt(np.vdot(x, x)))
