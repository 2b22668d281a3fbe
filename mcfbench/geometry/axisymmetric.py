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
Richardson extrapolation in ``h`` applies, see :func:`richardson`).
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

Quantities (all from the polygon, all symmetric rules with even error
expansions): the area of revolution of the polygon (frustum sum), the
enclosed volume (frustum volumes), the radius of the middle node (the neck
of a mirror-symmetric problem, which stays on ``z = 0``), the largest
height, and for a closed meridian the cross-section area.
"""

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.sparse.linalg import splu

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


# ---------------------------------------------------------------- measured quantities


def area(X):
    """Area of the surface of revolution of the polygon, ``sum pi (r_j + r_j+1) |x_j+1 - x_j|``.

    Parameters
    ----------
    X : (n, 2) float array, or (n + 1, 2) with the first node repeated for a closed meridian.

    Returns
    -------
    float
    """
    d = np.diff(X, axis=0)
    return float(np.pi * np.sum((X[1:, 0] + X[:-1, 0]) * np.hypot(d[:, 0], d[:, 1])))


def volume(X):
    """Volume swept by the polygon: ``|sum pi dz (r_j^2 + r_j r_j+1 + r_j+1^2) / 3|`` (frusta).

    For a meridian from pole to pole, or a closed one (pass it closed), the
    enclosed volume; for an open Dirichlet meridian, the volume between it,
    the axis and the planes of its ends.
    """
    r0, r1, dz = X[:-1, 0], X[1:, 0], np.diff(X[:, 1])
    return float(abs(np.pi * np.sum(dz * (r0 * r0 + r0 * r1 + r1 * r1)) / 3.0))


def cross_section(X):
    """Area enclosed by a closed meridian polygon (shoelace), ``X`` (n, 2) not repeated."""
    r, z = X[:, 0], X[:, 1]
    return float(0.5 * abs(np.sum(r * np.roll(z, -1) - np.roll(r, -1) * z)))


def _closed(X):
    return np.vstack([X, X[:1]])


def max_height(X, periodic=False):
    """Largest ``z`` of the meridian, by the quartic through the 5 nodes around the
    largest node (interior maximum), or the node itself at the ends."""
    z = X[:, 1]
    n = len(z)
    j = int(np.argmax(z))
    if not periodic and (j < 2 or j > n - 3):
        return float(z[j])
    k = (np.arange(j - 2, j + 3)) % n
    u = np.arange(-2, 3, dtype=float)
    p = np.polynomial.Polynomial.fit(u, z[k], 4, domain=[-2, 2], window=[-2, 2])
    crit = [c.real for c in p.deriv().roots() if abs(c.imag) < 1e-12 and -1.0 <= c.real <= 1.0]
    return float(max([z[j]] + [p(c) for c in crit]))


def measures(X, periodic=False):
    """The reference quantities of one meridian state.

    Returns
    -------
    dict
        ``area``, ``volume``, ``max_height``, ``mid_radius`` (``r`` of the
        middle node, the neck of a mirror-symmetric open meridian with an odd
        number of nodes), ``min_radius`` (smallest nodal ``r`` at an interior
        local minimum of ``r``, nan if none; a check that the neck is the
        middle node);
        for a closed meridian also ``cross_section`` and ``tube_radius``
        ``= sqrt(cross_section / pi)``.
    """
    Y = _closed(X) if periodic else X
    out = {"area": area(Y), "volume": volume(Y), "max_height": max_height(X, periodic)}
    r = X[:, 0]
    inner = (r[1:-1] <= r[:-2]) & (r[1:-1] <= r[2:]) if not periodic else np.zeros(0, bool)
    out["min_radius"] = float(r[1:-1][inner].min()) if inner.any() else float("nan")
    if periodic:
        out["cross_section"] = cross_section(X)
        out["tube_radius"] = math.sqrt(out["cross_section"] / math.pi)
    else:
        out["mid_radius"] = float(r[len(r) // 2])
    return out


# ---------------------------------------------------------------- Richardson extrapolation


def richardson(values, orders=(2, 4, 4, 6, 6), ratio=2.0):
    """Richardson table of a sequence computed with ``h, h/ratio, h/ratio^2, ...``.

    The default orders eliminate ``h^2``, then ``h^4 log h`` and ``h^4`` (two
    ``h^4`` steps: the first turns ``c h^4 log h`` into ``-c h^4 log(ratio) /
    15``, the second removes it), then ``h^6 log h`` and ``h^6``. Quantities
    at a pole (the ``"axis"`` ends) carry an ``h^4 log h`` term: for the
    sphere's pole height, orders (2, 4, 6, 8) stall at 5e-10 while (2, 4, 4, 6,
    6) reach 1e-14 (meshes 21 to 641). Quantities without such terms only
    lose one order.

    Parameters
    ----------
    values : (k,) array_like
        ``Q(h_i)``, coarse to fine, with ``Q(h) = Q + c_1 h^p1 + c_2 h^p2 + ...``.
    orders : sequence of float
        The exponents ``p1, p2, ...`` eliminated one per column (a repeated
        exponent eliminates ``h^p log h`` and ``h^p``).

    Returns
    -------
    value : float
        The most extrapolated entry (last row, last column).
    error : float
        Its error estimate: the difference to the entry one order lower in the
        same row (conservative: that entry's error).
    table : list of (k - c,) float arrays
        Column ``c`` eliminates ``orders[:c]``.
    """
    cols = [np.asarray(values, dtype=float)]
    for p in orders[: len(cols[0]) - 1]:
        prev = cols[-1]
        f = ratio ** p
        cols.append((f * prev[1:] - prev[:-1]) / (f - 1.0))
    value = float(cols[-1][-1])
    error = float(abs(cols[-1][-1] - cols[-2][-1])) if len(cols) > 1 else float("nan")
    return value, error, cols


def observed_orders(values, ratio=2.0):
    """Observed orders ``log(|Q_i - Q_i+1| / |Q_i+1 - Q_i+2|) / log(ratio)`` of a sequence."""
    d = np.abs(np.diff(np.asarray(values, dtype=float)))
    return np.log(d[:-1] / d[1:]) / np.log(ratio)


# ---------------------------------------------------------------- initial meridians


def dumbbell_profile(z, centre=1.2, neck=0.25, blend=0.05):
    """``r(z)^2`` of the suite's dumbbell (the formula of ``mcfbench.surfaces.dumbbell_profile``).

    ``k log(exp(p_+/k) + exp(p_-/k) + exp(q/k))``, ``p_+- = 1 - (z -+ c)^2``,
    ``q = n^2 (1 - (z/c)^8)``, ``k = blend``.
    """
    z = np.asarray(z, dtype=float)
    terms = np.stack([1.0 - (z - centre) ** 2, 1.0 - (z + centre) ** 2,
                      neck**2 * (1.0 - (z / centre) ** 8)])
    return blend * np.logaddexp.reduce(terms / blend, axis=0)


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
          (``mcfbench.surfaces.torus``);
        * ``dumbbell()``: ``r = sqrt(dumbbell_profile(z))`` from the top pole to
          the bottom one (``mcfbench.surfaces.dumbbell``), ``("axis", "axis")``;
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
        prof = angenent_profile()
        s = prof["length"] * np.arange(n) / n
        return prof["curve"](s), None, True
    raise ValueError(f"unknown shape {shape!r}")


# ---------------------------------------------------------------- the Angenent torus

ANGENENT_RHO0_PUBLISHED = 0.437123967096460
"""Inner radius of the Angenent torus's meridian as published (NOTES.md, "More exact
answers"; the normalisation ``H = x . nu / 2``, extinction at ``t = 1``)."""


def _angenent_rhs(s, y):
    """Shrinker meridian ODE by arc length (NOTES.md, "More exact answers")::

        rho' = sin a,  z' = cos a,  a' = (1/rho - rho/2) cos a + (z/2) sin a,

    with three quadratures appended: ``int rho``, ``int rho^2 z'``,
    ``int rho exp(-(rho^2 + z^2)/4)`` (area, volume, entropy).
    """
    rho, z, a = y[0], y[1], y[2]
    sa, ca = np.sin(a), np.cos(a)
    return [sa, ca, (1.0 / rho - 0.5 * rho) * ca + 0.5 * z * sa,
            rho, rho * rho * ca, rho * np.exp(-0.25 * (rho * rho + z * z))]


def _angenent_shoot(rho0, tol=1e-13):
    """Integrate from ``(rho0, 0)``, ``a = 0`` (upwards) to the next crossing of ``z = 0``."""

    def cross(s, y):
        return y[1]

    cross.terminal, cross.direction = True, -1
    sol = solve_ivp(_angenent_rhs, (0.0, 50.0), [rho0, 0.0, 0.0, 0.0, 0.0, 0.0],
                    method="DOP853", rtol=tol, atol=tol, events=cross, dense_output=True)
    if not sol.t_events[0].size:
        raise RuntimeError(f"the meridian from rho0 = {rho0} does not return to z = 0")
    return sol, float(sol.t_events[0][0]), sol.y_events[0][0]


def angenent_rho0(tol=1e-13):
    """Inner radius ``rho0`` of the Angenent torus by shooting.

    The meridian starts at ``(rho0, 0)`` vertically upwards and closes
    symmetrically iff it crosses ``z = 0`` again vertically (angle ``pi``);
    ``rho0`` is the root of ``a(crossing) - pi`` in ``[0.42, 0.45]`` (brentq,
    ``xtol = 1e-15``).

    Returns
    -------
    float
    """
    return brentq(lambda r0: _angenent_shoot(r0, tol)[2][2] - np.pi, 0.42, 0.45,
                  xtol=1e-15, rtol=1e-15)


def angenent_profile(rho0=None):
    """The Angenent torus at ``t = 0`` (extinct at ``t = 1``, ``M_t = sqrt(1 - t) M_0``).

    Parameters
    ----------
    rho0 : float, optional
        Inner radius; computed by :func:`angenent_rho0` if not given.

    Returns
    -------
    dict
        ``rho0``; ``rho_outer``; ``half_height`` (largest ``z``); ``length``
        (of the closed meridian); ``area`` ``= 2 pi int rho ds``; ``volume``;
        ``entropy`` ``= (4 pi)^-1 int exp(-|x|^2/4) dA``; ``curve`` (callable,
        arc length ``s`` (m,) -> (m, 2) points ``(rho, z)`` of the closed
        meridian, periodic with period ``length``, counter-clockwise from
        the inner point); ``upper`` (the dense ODE solution of the upper
        half, state ``(rho, z, a, ...)``), ``half_length``.
    """
    rho0 = angenent_rho0() if rho0 is None else float(rho0)
    sol, S, y_end = _angenent_shoot(rho0)
    ss = np.linspace(0.0, S, 4001)
    zz = sol.sol(ss)[1]

    def curve(s):
        s = np.mod(np.asarray(s, dtype=float), 2.0 * S)
        up = s <= S
        sig = np.where(up, s, 2.0 * S - s)
        y = sol.sol(sig)
        return np.column_stack([y[0], np.where(up, y[1], -y[1])])

    zmax = max_height(np.column_stack([sol.sol(ss)[0], zz]))
    return {"rho0": rho0, "rho_outer": float(y_end[0]), "half_height": float(zmax),
            "length": 2.0 * S, "half_length": S,
            "area": float(4.0 * np.pi * y_end[3]), "volume": float(2.0 * np.pi * abs(y_end[4])),
            "entropy": float(y_end[5]), "curve": curve, "upper": sol}


def angenent_area(t, profile=None):
    """Area of the Angenent torus at time ``t < 1``: ``(1 - t) area_0``."""
    profile = angenent_profile() if profile is None else profile
    return (1.0 - t) * profile["area"]


def angenent_distance(points, t, profile=None):
    """Unsigned distance of points to the Angenent torus ``M_t = sqrt(1 - t) M_0``.

    Parameters
    ----------
    points : (m, 3) or (m, 2) float array
        Points in space, or meridian points ``(rho, z)``.
    t : float
        Time, ``< 1``.

    Returns
    -------
    (m,) float array
        Nearest point on the upper half meridian (the torus is symmetric in
        ``z``) from a dense sample, refined by Newton's method on the arc length
        with the ODE's exact derivatives ``c' = (sin a, cos a)``,
        ``c'' = a' (cos a, -sin a)``.
    """
    from scipy.spatial import cKDTree

    profile = angenent_profile() if profile is None else profile
    P = np.asarray(points, dtype=float)
    if P.shape[1] == 3:
        P = np.column_stack([np.hypot(P[:, 0], P[:, 1]), P[:, 2]])
    scale = math.sqrt(1.0 - t)
    p = P / scale
    p[:, 1] = np.abs(p[:, 1])
    sol, S = profile["upper"], profile["half_length"]
    ss = np.linspace(0.0, S, 20001)
    Y = sol.sol(ss)
    s = ss[cKDTree(Y[:2].T).query(p)[1]]
    for _ in range(20):
        y = sol.sol(s)
        rho, z, a = y[0], y[1], y[2]
        d = np.column_stack([rho, z]) - p
        c1 = np.column_stack([np.sin(a), np.cos(a)])
        da = (1.0 / rho - 0.5 * rho) * np.cos(a) + 0.5 * z * np.sin(a)
        c2 = da[:, None] * np.column_stack([np.cos(a), -np.sin(a)])
        g = np.sum(d * c1, axis=1)
        hess = 1.0 + np.sum(d * c2, axis=1)
        step = g / np.where(hess > 0.1, hess, 1.0)
        s = np.clip(s - step, 0.0, S)
        if np.abs(step).max() < 1e-15:
            break
    y = sol.sol(s)
    return scale * np.hypot(y[0] - p[:, 0], y[1] - p[:, 1])


# ---------------------------------------------------------------- pinch times from the approach


def pinch_time_tube(t_levels, levels):
    """Extinction time of a closed meridian shrinking to a point (a thin torus's tube).

    Near extinction the tube is a thin round cylinder bent into a ring:
    ``d(pi rho^2)/dt = -2 pi + O(rho^2)`` for the cross-section radius
    ``rho = sqrt(A / pi)`` (the first term is ``-int kappa ds = -2 pi``; the
    parallel curvature ``cos(theta) / r`` integrates to ``O(rho^2)``), so
    ``t(rho) = T - rho^2/2 - a rho^4 - b rho^6 - ...``. Least squares for
    ``T, a, b`` on the given levels.

    Parameters
    ----------
    t_levels, levels : (k,) float arrays
        Times at which ``rho`` reached ``levels`` (decreasing), ``k >= 4``.

    Returns
    -------
    T, error : float
        ``T`` from the fit with ``rho^4, rho^6``; the error estimate is the
        largest change of ``T`` when the ``rho^6`` term or the largest level is
        dropped.
    """
    t, r = np.asarray(t_levels, float), np.asarray(levels, float)

    def fit(sel, powers):
        A = np.column_stack([np.ones(sel.sum())] + [-r[sel] ** p for p in powers])
        return np.linalg.lstsq(A, t[sel] + 0.5 * r[sel] ** 2, rcond=None)[0][0]

    allk = np.ones(len(t), bool)
    drop = allk.copy()
    drop[0] = False
    T = fit(allk, (4, 6))
    alts = [fit(allk, (4,)), fit(drop, (4, 6)), fit(drop, (4,))]
    return float(T), float(max(abs(a - T) for a in alts))


def pinch_time_neck(t_levels, levels, last=(4, 5, 6), ncoefs=(1, 2)):
    """Pinch time of a rotationally symmetric neck from the times it reached radii ``levels``.

    Fits the neckpinch asymptotics (Angenent and Velazquez; Angenent and
    Knopf: a round cylinder with logarithmic corrections)::

        r^2 = 2 D (1 + c_1 / L + c_2 / L^2),   D = T - t,   L = -log D,

    by nonlinear least squares (relative residuals) on the smallest ``k``
    levels. ``T`` is the fit with 2 coefficients on the smallest
    ``last[1]`` levels; the error estimate is the largest deviation of the
    fits with ``ncoefs`` coefficients on the smallest ``last`` levels.

    Returns
    -------
    T, error : float
    fits : list of (k, ncoef, T, coefficients)
    """
    from scipy.optimize import least_squares

    t, r2 = np.asarray(t_levels, float), np.asarray(levels, float) ** 2
    fits = []
    for k in last:
        for nc in ncoefs:
            tt, rr = t[-k:], r2[-k:]

            def res(p, tt=tt, rr=rr, nc=nc):
                D = np.maximum(p[0] - tt, 1e-300)
                L = -np.log(D)
                return 2.0 * D * (1.0 + sum(p[1 + i] / L ** (i + 1) for i in range(nc))) / rr - 1.0

            p0 = [t[-1] + 0.5 * r2[-1] * 1.3] + [0.0] * nc
            sol = least_squares(res, p0, x_scale=[r2[-1]] + [1.0] * nc,
                                bounds=([t[-1] + 1e-300] + [-np.inf] * nc, np.inf),
                                xtol=1e-15, ftol=1e-15, gtol=1e-15)
            fits.append((k, nc, float(sol.x[0]), sol.x[1:].tolist()))
    best = next(f[2] for f in fits if f[0] == last[1] and f[1] == 2)
    return best, max(abs(f[2] - best) for f in fits), fits


# ---------------------------------------------------------------- reference numbers

J01_SQUARED = 5.783185962946784
"""Square of the first zero of the Bessel function ``J_0`` (NOTES.md)."""


def catenoid_parameter(radius=1.0, half_height=0.5):
    """The stable root ``a`` of ``a cosh(h / a) = R`` (the larger one), by brentq."""
    x_crit = brentq(lambda x: x * math.tanh(x) - 1.0, 0.5, 2.0, xtol=1e-15)  # h/a at the fold
    a_fold = half_height / x_crit
    if a_fold * math.cosh(x_crit) > radius:
        raise ValueError(f"no catenoid spans circles of radius {radius} at +-{half_height}")
    return brentq(lambda a: a * math.cosh(half_height / a) - radius, a_fold, radius,
                  xtol=1e-16, rtol=4 * np.finfo(float).eps)


def catenoid_area(radius=1.0, half_height=0.5):
    """Area ``pi a (2 h + a sinh(2 h / a))`` of the stable catenoid (NOTES.md)."""
    a = catenoid_parameter(radius, half_height)
    return math.pi * a * (2.0 * half_height + a * math.sinh(2.0 * half_height / a))


def critical_aspect_ratio():
    """Largest ``h / R`` for which a catenoid spans circles of radius ``R`` at ``z = +-h``.

    ``h / R = x / cosh x`` at the root of ``x tanh x = 1`` (the fold of the
    catenoid family); 0.662743... Beyond it a cylinder between the circles
    pinches.
    """
    x = brentq(lambda x: x * math.tanh(x) - 1.0, 0.5, 2.0, xtol=1e-15)
    return x / math.cosh(x)


def _extrapolate(per_mesh, coarse_tight=None, coarse=None):
    """Richardson over meshes of each quantity; the time-tolerance effect (the
    coarsest mesh run with tolerances 10x tighter) is added to the error, which
    is floored at ``1e-14 |value|`` (rounding)."""
    out = {}
    for key in per_mesh[0]:
        vals = np.array([m[key] for m in per_mesh], dtype=float)
        if vals.ndim == 1:
            v, e, _ = richardson(vals)
            if coarse_tight is not None:
                e += abs(coarse_tight[key] - coarse[key])
            out[key] = (v, max(e, 1e-14 * abs(v)))  # floor: rounding of the sums
        else:
            rows = [richardson(vals[:, k]) for k in range(vals.shape[1])]
            err = np.array([r[1] for r in rows])
            if coarse_tight is not None:
                err = err + np.abs(np.asarray(coarse_tight[key]) - np.asarray(coarse[key]))
            value = np.array([r[0] for r in rows])
            out[key] = (value, np.maximum(err, 1e-14 * np.abs(value)))
    return out


def _fixed_time_run(shape, n, times, params, rtol, atol_factor=1.0):
    X, ends, per = initial_meridian(shape, n, **params)
    states = evolve(X, times, ends, per, rtol=rtol, atol=rtol * atol_factor)
    ms = [measures(Y, per) for Y in states]
    return {k: [m[k] for m in ms] for k in ms[0]}


def _pinch_run(shape, n, levels, times, params, rtol, quantity):
    X, ends, per = initial_meridian(shape, n, **params)
    t_lev, _, X_last, rec = evolve_until(X, quantity, levels, ends, per, rtol=rtol, atol=rtol,
                                         record_times=times)
    ms = [measures(Y, per) for Y in rec]
    out = {k: [m[k] for m in ms] for k in ms[0]}
    out["t_levels"] = t_lev
    last = measures(X_last, per)
    out["max_height_at_last_level"] = last["max_height"]
    return out


def _series_run(run, ns, *args, rtol=1e-11):
    per_mesh = [run(n, *args, rtol) for n in ns]
    coarse_tight = run(ns[0], *args, rtol / 10)
    return _extrapolate(per_mesh, coarse_tight, per_mesh[0]), per_mesh


def _mid(X):
    return float(X[len(X) // 2, 0])


def _tube(X):
    return math.sqrt(cross_section(X) / math.pi)


def reference_numbers(problems=("torus", "dumbbell", "catenoid", "hemisphere", "long_cylinder"),
                      quick=False):
    """Reference answers for the suite's axisymmetric problems (computed, nothing cached).

    Every number is ``(value, error_estimate)``: Richardson extrapolation over
    meshes ``n, 2n, 4n, 8n`` (orders 2, 4, 4, 6 of :func:`richardson`; error =
    difference to the next-lower column) plus the change when the coarsest mesh is rerun with
    time tolerances ten times tighter; pinch times add the spread of the
    asymptotic fits (:func:`pinch_time_tube`, :func:`pinch_time_neck`).

    Problems (initial shapes of ``mcfbench.problems``):

    * ``torus``: ``R = 2, r = 0.5``; ``volume``, ``area``, ``tube_radius``
      (``sqrt(cross-section / pi)``), ``max_height`` at ``times``; ``pinch_time``
      (the tube shrinks to a circle of radius ``ring_radius``).
    * ``dumbbell``: ``volume``, ``area``, ``mid_radius`` (the neck on
      ``z = 0``), ``max_height`` at ``times``; ``pinch_time``.
    * ``catenoid``: cylinder ``R = 1, h = 0.5`` between fixed circles:
      ``mid_radius`` (neck) and ``area`` at ``times``, the last one (t = 8) at
      the steady state, with the exact catenoid ``a``, its area.
    * ``hemisphere``: ``R = 1``, equator fixed: ``max_height`` at ``times``;
      ``decay_rate = log(z(1.5) / z(2)) / 0.5`` and ``decay_rate_late`` (from
      ``t = 2`` to 2.5) against ``j01^2 / R^2`` (they differ from it by the
      nonlinear ``O(z^2)`` correction, 3e-8 and 1e-10).
    * ``long_cylinder``: ``R = 1, h = 1`` (``h / R`` beyond
      :func:`critical_aspect_ratio`): neck at ``times`` and ``pinch_time``.

    Parameters
    ----------
    problems : sequence of str
    quick : bool
        Coarser meshes (a smoke test: about 10 s, errors far larger).

    Returns
    -------
    dict
        ``problem -> {quantity: (value, error)}`` (arrays over ``times`` for
        time series) plus ``times`` and setting entries.
    """
    out = {}
    neck_levels = 0.1 * 2.0 ** (-0.5 * np.arange(10 if not quick else 6))
    if "torus" in problems:
        ns = (128, 256, 512, 1024) if not quick else (32, 64, 128)
        levels = 0.1 * 2.0 ** (-0.5 * np.arange(9))
        times = (0.025, 0.05, 0.075, 0.1)
        ex, _ = _series_run(lambda n, rtol: _pinch_run(
            "torus", n, levels, times, {"R": 2.0, "r": 0.5}, rtol, _tube), ns)
        T, eT = pinch_time_tube(ex["t_levels"][0], levels)
        res = {k: ex[k] for k in ("volume", "area", "tube_radius", "max_height")}
        res.update(times=times, meshes=ns, levels=levels, t_levels=ex["t_levels"],
                   pinch_time=(T, eT + float(ex["t_levels"][1].max())))
        out["torus"] = res
    if "dumbbell" in problems:
        ns = (1601, 3201, 6401, 12801) if not quick else (201, 401, 801)
        times = (0.02, 0.04, 0.06, 0.08)
        ex, _ = _series_run(lambda n, rtol: _pinch_run(
            "dumbbell", n, neck_levels, times, {}, rtol, _mid), ns)
        T, eT, _fits = pinch_time_neck(ex["t_levels"][0], neck_levels,
                                       last=(4, 5, 6) if not quick else (3, 4, 5))
        res = {k: ex[k] for k in ("volume", "area", "mid_radius", "max_height")}
        res.update(times=times, meshes=ns, levels=neck_levels, t_levels=ex["t_levels"],
                   max_height_at_last_level=ex["max_height_at_last_level"],
                   pinch_time=(T, eT + float(ex["t_levels"][1].max())))
        out["dumbbell"] = res
    if "catenoid" in problems:
        ns = (33, 65, 129, 257, 513) if not quick else (17, 33, 65)
        times = (0.1, 0.25, 0.5, 1.0, 1.5, 8.0)
        ex, _ = _series_run(lambda n, rtol: _fixed_time_run(
            "cylinder", n, times, {"radius": 1.0, "half_height": 0.5}, rtol), ns)
        out["catenoid"] = {"mid_radius": ex["mid_radius"], "area": ex["area"],
                           "volume": ex["volume"], "times": times, "meshes": ns,
                           "exact_neck": catenoid_parameter(1.0, 0.5),
                           "exact_area": catenoid_area(1.0, 0.5)}
    if "hemisphere" in problems:
        ns = (33, 65, 129, 257, 513) if not quick else (17, 33, 65)
        times = (0.1, 0.25, 0.5, 1.0, 1.5, 2.0, 2.5)

        def run(n, rtol):  # heights down to 1e-6: absolute tolerance 1e-5 rtol
            r = _fixed_time_run("hemisphere", n, times, {"radius": 1.0}, rtol, 1e-5)
            z = r["max_height"]
            r["decay_rate"] = math.log(z[4] / z[5]) / 0.5
            r["decay_rate_late"] = math.log(z[5] / z[6]) / 0.5
            return r

        ex, _ = _series_run(run, ns)
        out["hemisphere"] = {"max_height": ex["max_height"], "area": ex["area"],
                             "volume": ex["volume"], "decay_rate": ex["decay_rate"],
                             "decay_rate_late": ex["decay_rate_late"], "times": times,
                             "meshes": ns, "exact_rate": J01_SQUARED}
    if "long_cylinder" in problems:
        ns = (801, 1601, 3201, 6401) if not quick else (101, 201, 401)
        times = (0.05, 0.1, 0.15)
        ex, _ = _series_run(lambda n, rtol: _pinch_run(
            "cylinder", n, neck_levels, times, {"radius": 1.0, "half_height": 1.0}, rtol, _mid), ns)
        T, eT, _fits = pinch_time_neck(ex["t_levels"][0], neck_levels,
                                       last=(4, 5, 6) if not quick else (3, 4, 5))
        out["long_cylinder"] = {"radius": 1.0, "half_height": 1.0,
                                "critical_ratio": critical_aspect_ratio(),
                                "mid_radius": ex["mid_radius"], "area": ex["area"],
                                "times": times, "meshes": ns, "levels": neck_levels,
                                "t_levels": ex["t_levels"],
                                "pinch_time": (T, eT + float(ex["t_levels"][1].max()))}
    return out


def format_reference_table(ref):
    """Plain-text table of :func:`reference_numbers` (value and error estimate per row).

    Returns
    -------
    str
    """
    lines = [f"{'problem':<14}{'quantity':<26}{'t':>8}  {'value':>22}  {'error est.':>10}"]
    for prob, res in ref.items():
        times = res.get("times", ())
        for key, item in res.items():
            if not (isinstance(item, tuple) and len(item) == 2) or key == "times":
                continue
            value, err = item
            if np.ndim(value) == 1 and len(value) == len(times):
                for t, v, e in zip(times, value, err):
                    lines.append(f"{prob:<14}{key:<26}{t:>8g}  {v:>22.15g}  {e:>10.1e}")
            elif np.ndim(value) == 0:
                lines.append(f"{prob:<14}{key:<26}{'':>8}  {float(value):>22.15g}  {float(err):>10.1e}")
        for key in ("exact_neck", "exact_area", "exact_rate", "critical_ratio"):
            if key in res:
                lines.append(f"{prob:<14}{key:<26}{'':>8}  {res[key]:>22.15g}  {'exact':>10}")
    return "\n".join(lines)
