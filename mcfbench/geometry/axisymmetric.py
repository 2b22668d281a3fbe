"""Reference solutions of axisymmetric mean curvature flow from the meridian curve.

A surface of revolution about the ``z`` axis is given by its meridian curve
``x(u, t) = (r(u, t), z(u, t))``, ``u`` in ``[0, 1]``. Mean curvature flow
(normal velocity ``V = H``, ``H`` the SUM of the principal curvatures, so a
sphere has ``r(t) = sqrt(R^2 - 4 t)``) is solved in the DeTurck-type form
(tangential velocity from ``x_uu / |x_u|^2``, as in the axisymmetric
schemes of Barrett, Deckelnick and Nuernberg, IMA J. Numer. Anal. 41 (2021),
arXiv 1911.05398, and Barrett, Garcke and Nuernberg, Numer. Math. 141 (2019)
791-837; only their abstracts could be consulted here, so no equation
number of theirs is cited: (A1)-(A3) are derived in this module and checked
against the sphere, the catenoid and the Angenent torus)::

    x_t = x_uu / |x_u|^2 - (nu . e_1) / (x . e_1) nu,          (A1)

``nu`` a unit normal of the meridian (the term is even in ``nu``). The normal
part of (A1) is ``H`` (meridian curvature plus ``nu . e_1 / r``); the
tangential part ``(x_uu . tau) / |x_u|^2`` drives ``|x_u|`` towards a
constant, i.e. the nodes towards equal arc length. In components, with
``nu = (-z_u, r_u) / |x_u|``, (A1) is::

    r_t = (r_uu - z_u^2 / r) / |x_u|^2,                        (A2)
    z_t = (z_uu + z_u r_u / r) / |x_u|^2.

Discretisation (this module, not BDN's finite elements): central finite
differences on the uniform grid ``u_j = j / N`` (second order; the scheme
and every measured quantity are symmetric, so the error expands in even
powers ``h^2, h^4, ...``, with an extra ``h^4 log h`` term at a pole, and
Richardson extrapolation in ``h`` applies, see
:func:`mcfbench.geometry.extrapolation.richardson`; the reference numbers are in
:mod:`mcfbench.geometry.axisymmetric_references`, the Angenent torus in
:mod:`mcfbench.geometry.angenent`).
Both (A2) are invariant under ``u -> c u``, so index units are used.

Ends of the meridian:

* ``"axis"`` (a pole of a genus-0 surface): ``r = 0`` and the curve meets
  the axis at a right angle; ghost nodes by the reflection
  ``r_{-1} = -r_1, z_{-1} = z_1``. At the pole both principal curvatures
  equal the meridian curvature, ``H = 2 kappa``, and (A1) becomes
  ``z_t = 2 z_uu / r_u^2``, discretely ``z_t = 4 (z_1 - z_0) / r_1^2`` (A3).
* ``"fixed"``: a Dirichlet end (boundary circle of a catenoid or of the
  hemisphere's equator).
* ``periodic=True``: a closed meridian (a torus).

Time stepping, two choices:

* ``"cn"``: Crank-Nicolson (trapezoidal rule) with a fixed step ``tau``,
  solved by a simplified Newton iteration to ``newton_tol``; order 2 with
  an error expansion in even powers of ``tau`` (a symmetric one-step
  method), so it can be Richardson-extrapolated in ``tau`` too.
* ``"radau"``: scipy's adaptive Radau IIA (order 5) with tolerances
  ``rtol = atol = 1e-11`` by default, so that the time error is far below
  the space error; used up to the pinch, where fixed steps would waste work.

Jacobians are built by finite differences over a colouring of the band
(bandwidth 3 in the interleaved ordering ``r_0, z_0, r_1, z_1, ...``; the
periodic case adds corner blocks) and factorised with ``splu``.

The quantities measured of a meridian state are in
:mod:`mcfbench.geometry.meridians`.
"""

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.optimize import brentq
from scipy.sparse.linalg import splu

from mcfbench.geometry.shapes import dumbbell_profile

# ---------------------------------------------------------------- the velocity


def velocity(X, ends=("axis", "axis"), periodic=False):
    """Semi-discrete velocity (A2)-(A3) of the meridian nodes.

    Parameters
    ----------
    X : (n, 2) float array
        Nodes ``(r_j, z_j)``, ``r_j > 0`` except at ``"axis"`` ends.
    ends : tuple of {"axis", "fixed"}
        Type of the first and last node (ignored if ``periodic``).
    periodic : bool
        Closed meridian (node ``n - 1`` joined to node 0).

    Returns
    -------
    (n, 2) float array
        ``dX/dt`` by (A2) in index units (invariant under ``u -> c u``).
    """
    X = np.asarray(X, dtype=float)
    r, z = X[:, 0], X[:, 1]
    V = np.zeros_like(X)
    if periodic:
        rm, rp, zm, zp = np.roll(r, 1), np.roll(r, -1), np.roll(z, 1), np.roll(z, -1)
        idx = slice(None)
        rc, zc = r, z
    else:
        rm, rp, zm, zp = r[:-2], r[2:], z[:-2], z[2:]
        idx = slice(1, -1)
        rc, zc = r[1:-1], z[1:-1]
    ru, zu = 0.5 * (rp - rm), 0.5 * (zp - zm)  # central differences, (A2)
    ruu, zuu = rp - 2.0 * rc + rm, zp - 2.0 * zc + zm
    q = ru * ru + zu * zu
    V[idx, 0] = (ruu - zu * zu / rc) / q
    V[idx, 1] = (zuu + zu * ru / rc) / q
    if not periodic:
        if ends[0] == "axis":  # (A3) with the ghost r_{-1} = -r_1, z_{-1} = z_1
            V[0, 1] = 4.0 * (z[1] - z[0]) / r[1] ** 2
        if ends[1] == "axis":
            V[-1, 1] = 4.0 * (z[-2] - z[-1]) / r[-2] ** 2
    return V


def _colouring(m, periodic):
    """Colour ``k -> c[k]`` of the ``m`` unknowns so that unknowns within
    distance 3 (cyclically if ``periodic``) get different colours."""
    if not periodic:
        return np.arange(m) % 7, 7
    ncol = next(c for c in range(7, m + 1) if m % c == 0)
    return np.arange(m) % ncol, ncol


def _pattern(n, periodic):
    """Rows and columns of the band (width 3, plus corners if periodic)."""
    m = 2 * n
    k = np.arange(m)
    rows, cols = [], []
    for d in range(-3, 4):
        c = k + d
        ok = slice(None) if periodic else (c >= 0) & (c < m)
        rows.append(k[ok])
        cols.append((c % m)[ok] if periodic else c[ok])
    rows, cols = np.concatenate(rows), np.concatenate(cols)
    key = np.unique(rows * m + cols)
    return key // m, key % m


@dataclass
class _System:
    """The ODE ``y' = f(y)``, ``y`` the flattened nodes, with its sparse Jacobian."""

    n: int
    ends: tuple = ("axis", "axis")
    periodic: bool = False
    nfev: int = 0
    _pat: tuple = field(default=None, repr=False)

    def __post_init__(self):
        self._pat = _pattern(self.n, self.periodic)
        self._col, self._ncol = _colouring(2 * self.n, self.periodic)

    def f(self, t, y):
        self.nfev += 1
        return velocity(y.reshape(-1, 2), self.ends, self.periodic).ravel()

    def jac(self, t, y):
        """Sparse (2n, 2n) Jacobian by coloured forward differences."""
        f0 = self.f(t, y)
        rows, cols = self._pat
        vals = np.empty(len(rows))
        colour_of_col = self._col[cols]
        for c in range(self._ncol):
            sel = self._col == c
            dy = np.zeros_like(y)
            dy[sel] = 1e-7 * np.maximum(1.0, np.abs(y[sel]))
            df = self.f(t, y + dy) - f0
            here = colour_of_col == c  # entry (i, j): one unknown j of colour c per row
            vals[here] = df[rows[here]] / dy[cols[here]]
        return sp.csc_matrix((vals, (rows, cols)), shape=(2 * self.n, 2 * self.n))


# ---------------------------------------------------------------- time stepping


def _cn_step(system, y, tau, newton_tol=1e-13, max_iter=30):
    """One Crank-Nicolson step ``y1 = y + tau/2 (f(y) + f(y1))`` by simplified Newton
    (Jacobian at ``y``, factorised once per step)."""
    f0 = system.f(0.0, y)
    J = system.jac(0.0, y)
    lu = splu((sp.identity(len(y), format="csc") - 0.5 * tau * J).tocsc())
    y1 = y + tau * f0  # explicit Euler predictor
    scale = max(1.0, float(np.abs(y).max()))
    for _ in range(max_iter):
        g = y1 - y - 0.5 * tau * (f0 + system.f(0.0, y1))
        d = lu.solve(-g)
        y1 = y1 + d
        if np.abs(d).max() <= newton_tol * scale:
            return y1
    raise RuntimeError(f"Crank-Nicolson Newton iteration did not converge (|d| = "
                       f"{np.abs(d).max():.2e}); reduce tau")


def _radau_to(system, y, t0, t1, rtol, atol, first_step=None):
    """Adaptive Radau IIA from ``t0`` to exactly ``t1``; returns ``(y1, last_step)``."""
    from scipy.integrate import Radau

    solver = Radau(system.f, t0, y, t1, rtol=rtol, atol=atol, jac=system.jac,
                   first_step=first_step)
    last = first_step
    while solver.status == "running":
        msg = solver.step()
        if solver.status == "failed":
            raise RuntimeError(f"Radau failed at t = {solver.t:.6g}: {msg}")
        last = solver.step_size or last
    return solver.y.copy(), last


def evolve(X0, times, ends=("axis", "axis"), periodic=False, method="radau", tau=None,
           rtol=1e-11, atol=1e-11):
    """Flow the meridian ``X0`` by (A2) and return its nodes at ``times``.

    Parameters
    ----------
    X0 : (n, 2) float array
        Initial nodes (see :func:`initial_meridian`).
    times : sequence of float
        Increasing output times ``> 0``.
    ends, periodic
        As in :func:`velocity`.
    method : {"radau", "cn"}
        Adaptive Radau IIA (``rtol``, ``atol``) or Crank-Nicolson with the fixed
        step ``tau`` (every output time must be a whole multiple of ``tau``).

    Returns
    -------
    list of (n, 2) float arrays
        The nodes at each of ``times``.
    """
    system = _System(len(X0), tuple(ends or ()), bool(periodic))
    y, t, out, step = np.asarray(X0, float).ravel().copy(), 0.0, [], None
    for t1 in times:
        if method == "cn":
            k = round((t1 - t) / tau)
            if not math.isclose(t + k * tau, t1, rel_tol=1e-12, abs_tol=1e-14):
                raise ValueError(f"output time {t1} is not a multiple of tau = {tau}")
            for _ in range(k):
                y = _cn_step(system, y, tau)
        elif method == "radau":
            y, step = _radau_to(system, y, t, t1, rtol, atol, step)
        else:
            raise ValueError(f"method must be 'radau' or 'cn', got {method!r}")
        t = t1
        out.append(y.reshape(-1, 2).copy())
    return out


def evolve_until(X0, quantity, levels, ends=("axis", "axis"), periodic=False, rtol=1e-11,
                 atol=1e-11, t_max=10.0, record_times=()):
    """Flow by adaptive Radau until ``quantity(X)`` has fallen through each of ``levels``.

    Parameters
    ----------
    X0 : (n, 2) float array
    quantity : callable
        ``quantity(X) -> float``, decreasing along the flow (a neck radius).
    levels : sequence of float
        Decreasing; the times ``t_k`` with ``quantity(X(t_k)) = levels[k]`` are found.
    record_times : sequence of float
        Increasing times at which the nodes are also returned (each by a fresh
        integration from the last accepted step before it).

    Returns
    -------
    t_levels : (k,) float array
        Each by secant steps, every one a fresh Radau integration from the
        last accepted step before the crossing, to ``|quantity - level| < 1e-13``
        (the main integration is not disturbed).
    history : (m, 2) float array
        ``(t, quantity)`` at every accepted step up to the last crossing.
    X : (n, 2) float array
        The nodes at ``t_levels[-1]``.
    recorded : list of (n, 2) float arrays
        The nodes at ``record_times`` (only if ``record_times`` is given).
    """
    from scipy.integrate import Radau

    pending, recorded = list(record_times), []

    levels = list(levels)
    system = _System(len(X0), tuple(ends or ()), bool(periodic))
    y = np.asarray(X0, float).ravel().copy()
    solver = Radau(system.f, 0.0, y, t_max, rtol=rtol, atol=atol, jac=system.jac)
    hist = [(0.0, quantity(X0))]
    found, X_last = [], None
    while levels:
        t_prev, y_prev, q_prev = solver.t, solver.y.copy(), hist[-1][1]
        msg = solver.step()
        if solver.status == "failed":
            raise RuntimeError(f"Radau failed at t = {solver.t:.6g}: {msg}")
        qv = quantity(solver.y.reshape(-1, 2))
        if not np.isfinite(qv):
            raise RuntimeError(f"non-finite quantity at t = {solver.t:.6g}")
        hist.append((solver.t, qv))
        while pending and solver.t >= pending[0]:
            tr = pending.pop(0)
            yr = solver.y.copy() if tr == solver.t else _radau_to(
                system, y_prev, t_prev, tr, rtol, atol, (tr - t_prev) / 4)[0]
            recorded.append(yr.reshape(-1, 2))
        while levels and qv <= levels[0]:
            level = levels.pop(0)
            ta, qa, tb, qb = t_prev, q_prev, solver.t, qv
            yb = solver.y.copy()
            for _ in range(40):  # secant on t in [t_prev, solver.t]
                tc = tb - (qb - level) * (tb - ta) / (qb - qa)
                yc, _ = _radau_to(system, y_prev, t_prev, tc, rtol, atol, (tc - t_prev) / 4)
                qc = quantity(yc.reshape(-1, 2))
                ta, qa, tb, qb, yb = tb, qb, tc, qc, yc
                if abs(qc - level) < 1e-13 or tb == ta:
                    break
            found.append(tb)
            X_last = yb.reshape(-1, 2)
        if levels and solver.status == "finished":
            raise RuntimeError(f"{levels[0]} not reached before t_max = {t_max}")
    if pending:
        raise ValueError(f"record times {pending} are after the last level was reached")
    if record_times:
        return np.array(found), np.array(hist), X_last, recorded
    return np.array(found), np.array(hist), X_last


# ---------------------------------------------------------------- Richardson extrapolation


# ---------------------------------------------------------------- initial meridians


_GL_X, _GL_W = np.polynomial.legendre.leggauss(16)


def arclength_nodes(curve, speed, n, panels=4096):
    """Nodes at equal arc length along a smooth curve ``s -> curve(s)``, ``s`` in ``[0, 1]``.

    Arc length by composite 16-point Gauss-Legendre on ``panels`` panels and
    inside the last panel (exact to rounding for analytic curves); the
    parameter of each node by Newton's method. The map from the arc-length
    fraction to the curve does not depend on ``n``, so the nodes of all
    refinements sample one smooth parametrisation (needed for Richardson).

    Parameters
    ----------
    curve : callable
        ``curve(s) -> (m, 2)`` array for ``s`` of shape (m,).
    speed : callable
        ``|curve'(s)|``, shape (m,).
    n : int
        Number of nodes, including both ends (``s = 0`` and ``s = 1``).

    Returns
    -------
    (n, 2) float array
    """
    edges = np.linspace(0.0, 1.0, panels + 1)

    def integral(a, b):  # int_a^b speed, vectorised over a, b
        mid, half = 0.5 * (a + b), 0.5 * (b - a)
        pts = mid[:, None] + half[:, None] * _GL_X[None, :]
        return half * (speed(pts.ravel()).reshape(pts.shape) @ _GL_W)

    cum = np.r_[0.0, np.cumsum(integral(edges[:-1], edges[1:]))]
    target = cum[-1] * np.arange(n) / (n - 1)
    s = np.interp(target, cum, edges)
    for _ in range(50):
        k = np.clip(np.searchsorted(edges, s, side="right") - 1, 0, panels - 1)
        g = cum[k] + integral(edges[k], s) - target
        ds = g / speed(s)
        s = np.clip(s - ds, 0.0, 1.0)
        if np.abs(ds).max() < 1e-15:
            break
    X = curve(s)
    return X


def initial_meridian(shape, n, **params):
    """The meridian nodes of one of the suite's initial surfaces, equally spaced in arc length.

    Parameters
    ----------
    shape : {"sphere", "torus", "dumbbell", "cylinder", "hemisphere", "angenent"}
        * ``sphere(radius=1)``: pole to pole, ends ``("axis", "axis")``;
        * ``torus(R=2, r=0.5)``: the circle ``(R + r cos v, r sin v)``, closed
          (``mcfbench.geometry.shapes.torus``);
        * ``dumbbell()``: ``r = sqrt(dumbbell_profile(z))`` from the top pole to
          the bottom one (``mcfbench.geometry.shapes.dumbbell``), ``("axis", "axis")``;
        * ``cylinder(radius=1, half_height=0.5)``: ``r = R`` from ``z = -h`` to
          ``h``, ``("fixed", "fixed")`` (the ``catenoid`` problem);
        * ``hemisphere(radius=1)``: pole to equator, ``("axis", "fixed")``;
        * ``angenent()``: the Angenent torus of :func:`angenent_profile`, closed.
    n : int
        Nodes (open meridians: including both ends; use an odd ``n`` to have a
        middle node on the mirror plane ``z = 0``).

    Returns
    -------
    X : (n, 2) float array
    ends : tuple of str
    periodic : bool
    """
    if shape == "sphere":
        R = params.get("radius", 1.0)
        s = np.pi * np.arange(n) / (n - 1)
        X = np.column_stack([R * np.sin(s), R * np.cos(s)])
        X[[0, -1], 0] = 0.0
        return X, ("axis", "axis"), False
    if shape == "torus":
        R, r = params.get("R", 2.0), params.get("r", 0.5)
        v = 2.0 * np.pi * np.arange(n) / n
        return np.column_stack([R + r * np.cos(v), r * np.sin(v)]), None, True
    if shape == "cylinder":
        R, h = params.get("radius", 1.0), params.get("half_height", 0.5)
        z = np.linspace(-h, h, n)
        z[(n - 1) // 2] = 0.0 if n % 2 else z[(n - 1) // 2]
        return np.column_stack([np.full(n, R), z]), ("fixed", "fixed"), False
    if shape == "hemisphere":
        R = params.get("radius", 1.0)
        s = 0.5 * np.pi * np.arange(n) / (n - 1)
        X = np.column_stack([R * np.sin(s), R * np.cos(s)])
        X[0, 0], X[-1] = 0.0, (R, 0.0)
        return X, ("axis", "fixed"), False
    if shape == "dumbbell":
        L = brentq(dumbbell_profile, 1.5, 4.0, xtol=1e-15)

        def curve(s):
            z = L * np.cos(np.pi * s)
            return np.column_stack([np.sqrt(np.maximum(dumbbell_profile(z), 0.0)), z])

        def speed(s):  # |d/ds (sqrt(p(z)), z)|, z = L cos(pi s), p' by the formula's chain rule
            z = L * np.cos(np.pi * s)
            dz = -np.pi * L * np.sin(np.pi * s)
            p = dumbbell_profile(z)
            c, nk, k = 1.2, 0.25, 0.05
            terms = np.stack([1.0 - (z - c) ** 2, 1.0 - (z + c) ** 2, nk**2 * (1.0 - (z / c) ** 8)])
            w = np.exp((terms - p[None]) / k)  # softmax weights
            dp = w[0] * (-2.0 * (z - c)) + w[1] * (-2.0 * (z + c)) + w[2] * (-8.0 * nk**2 * z**7 / c**8)
            # d sqrt(p)/ds = p' dz / (2 sqrt p); near the poles p ~ 0: use the limit with p'/sqrt(p)
            with np.errstate(divide="ignore", invalid="ignore"):
                dr = np.where(p > 1e-300, dp * dz / (2.0 * np.sqrt(np.maximum(p, 1e-300))), 0.0)
            # at the poles themselves sqrt(p) ~ |L - z|^(1/2) and dz -> 0: the limit is finite
            lim = np.sqrt(np.abs(dp) * np.pi**2 * L / 2.0) / np.sqrt(2.0)
            dr = np.where((s <= 0.0) | (s >= 1.0), lim * np.sign(0.5 - s), dr)
            return np.hypot(dr, dz)

        X = arclength_nodes(curve, speed, n)
        X[[0, -1], 0] = 0.0
        X[[0, -1], 1] = [L, -L]
        if n % 2:
            X[n // 2, 1] = 0.0
        return X, ("axis", "axis"), False
    if shape == "angenent":
        from mcfbench.geometry.angenent import angenent_profile

        prof = angenent_profile()
        s = prof["length"] * np.arange(n) / n
        return prof["curve"](s), None, True
    raise ValueError(f"unknown shape {shape!r}")


# ---------------------------------------------------------------- the Angenent torus


# ---------------------------------------------------------------- pinch times from the approach


# ---------------------------------------------------------------- reference numbers


