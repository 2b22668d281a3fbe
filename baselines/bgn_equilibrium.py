"""BGN's tangential equilibrium: the vertex positions BGN's steps relax a mesh to.

The rows of BGN's system (B4) (:mod:`baselines.bgn`) tangential to ``omega_k`` read
(``P`` has rank 1 per vertex, along ``omega_k``)::

    E_k^T sum_j A_kj X_j^{m+1} = 0,   E_k = (e_k1, e_k2), e_ki . omega_k = 0    (E1)

with ``A`` and ``omega`` those of ``Gamma^m``: whatever ``tau``, a step puts every free
vertex where the stiffness of the previous surface pulls it along no tangent direction
of that surface. A state at which (E1) holds with its own operators,

    E(X)^T A(X) X = 0,                                                        (E2)

is the equilibrium of BGN's tangential motion; the steps approach it as a fixed-point
iteration (the operators lag one step), not in time: the tangential positions after
``m`` steps depend on ``m``, not on ``m tau`` (derived here from (B4); measured: on the
level-2 icosphere the lagged iteration's increment falls by 1.6 % an iteration, so a
start-up that takes other steps than the run's own leaves its vertices elsewhere
tangentially, ``baselines/README.md``, bgn-bdf3). The iteration with no normal motion
(the limit ``tau -> 0`` of (B4): ``X + E t`` with ``t`` solving (E1) at ``X``)::

    (E^T A E) t = -E^T A X,    X <- X + E t                                    (E3)

a 2n x 2n symmetric system per iteration (``A`` of one coordinate acting on each, the
blocks ``(E^T A E)_{kj}^{ab} = A_kj e_ka . e_jb``), Dirichlet vertices left out
(``t = 0``). Each (E3) is the limit of a BGN step, whose area never grows (BGN 2008,
Theorem 2.3, for every ``tau``). :func:`equilibrium` accelerates (E3) by Anderson
mixing (D. G. Anderson, J. ACM 12 (1965) 547-560; the form of H. F. Walker, P. Ni,
SIAM J. Numer. Anal. 49 (2011) 1715-1735, Section 2, with a window of ``MEMORY``).
"""

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve

MEMORY = 6
"""Anderson mixing's window: the last ``MEMORY`` increments (Walker and Ni's ``m``)."""

STALL = 10
""":func:`equilibrium` gives up when this many iterations have not halved the increment
(measured: the level-3 icosphere's falls from 1e-2 to 1e-11 in 38, a factor 0.58 an
iteration on average; the real nut's does not fall)."""


def tangent_frames(omega):
    """Two unit vectors per vertex, orthonormal and orthogonal to ``omega``.

    Parameters
    ----------
    omega : (n, 3) float array
        Non-zero normals (BGN's (B3)).

    Returns
    -------
    e1, e2 : (n, 3) float arrays
    """
    w = omega / np.linalg.norm(omega, axis=1, keepdims=True)
    helper = np.where(np.abs(w[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    e1 = np.cross(w, helper)
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    return e1, np.cross(w, e1)


def tangential_increment(L, omega, X, free):
    """``E t`` of one iteration (E3) at ``X``.

    Parameters
    ----------
    L : (n, n) scipy.sparse matrix
        The stiffness ``A`` of one coordinate at ``X`` (symmetric).
    omega : (n, 3) float array
        The normals (B3) at ``X``.
    X : (3, n) float array
    free : (n,) bool array
        The vertices that move (not Dirichlet).

    Returns
    -------
    (3, n) float array
        Tangential at every vertex, zero at the fixed ones.
    """
    n = X.shape[1]
    e = tangent_frames(omega)
    C = L.tocoo()
    blocks = [[sp.csr_matrix((C.data * np.einsum("ij,ij->i", e[a][C.row], e[b][C.col]),
                              (C.row, C.col)), shape=(n, n)) for b in range(2)]
              for a in range(2)]
    K = sp.bmat(blocks, format="csr")
    LX = L @ X.T
    r = np.concatenate([np.einsum("ij,ij->i", e[a], LX) for a in range(2)])
    keep = np.concatenate([free, free])
    t = np.zeros(2 * n)
    if keep.any():
        t[keep] = spsolve(K[keep][:, keep].tocsc(), -r[keep])
    return (e[0] * t[:n, None] + e[1] * t[n:, None]).T


def equilibrium(increment, X, tol, maxit, reach):
    """The state (E2) from ``X`` by (E3) with Anderson mixing.

    Parameters
    ----------
    increment : callable
        ``increment(X) -> D`` (3, n): :func:`tangential_increment` at ``X``.
    X : (3, n) float array
    tol : float
        Converged when the largest coordinate of the increment is below it.
    maxit : int
    reach : float
        Given up (not converged) once an iterate has a coordinate this far from
        ``X``'s (an equilibrium that far along the surface is another mesh, no
        relaxation of this one), or once ``STALL`` iterations have not halved the
        increment.

    Returns
    -------
    X : (3, n) float array
        The last iterate.
    converged : bool
    iterations : int
    """
    x0 = np.asarray(X, float).ravel()
    x = x0.copy()
    xs, fs, sizes = [], [], []
    for it in range(maxit):
        f = increment(x.reshape(X.shape)).ravel()
        sizes.append(np.abs(f).max())
        if not np.isfinite(sizes[-1]):
            return x.reshape(X.shape), False, it
        if sizes[-1] < tol:
            return x.reshape(X.shape), True, it
        if np.abs(x - x0).max() > reach or \
                (it >= STALL and sizes[-1] > 0.5 * sizes[-1 - STALL]):
            return x.reshape(X.shape), False, it
        xs, fs = (xs + [x.copy()])[-MEMORY - 1:], (fs + [f])[-MEMORY - 1:]
        if len(fs) > 1:
            dF, dX = np.diff(fs, axis=0).T, np.diff(xs, axis=0).T
            gamma = np.linalg.lstsq(dF, f, rcond=None)[0]
            x = x + f - (dX + dF) @ gamma
        else:
            x = x + f
    return x.reshape(X.shape), False, maxit
