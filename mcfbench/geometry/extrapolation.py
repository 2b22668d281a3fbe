"""Richardson extrapolation and observed orders of a refinement series, and pinch times extrapolated from the approach to a singularity (a torus tube or a neck shrinking to a circle or a point). Used by the axisymmetric references (:mod:`mcfbench.geometry.axisymmetric_references`)."""

import numpy as np


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


def pinch_time_tube(t_levels, levels):
    """Extinction time of a closed meridian shrinking to a point (a thin torus's tube).

    Near extinction the tube is a thin round cylinder bent into a ring:
    ``d(pi rho^2)/dt = -2 pi + O(rho^2)`` for the cross-section radius
    ``rho = sqrt(A / pi)`` (the first term is ``-int kappa ds = -2 pi``; the
    parallel curvature ``cos(theta) / r`` integrates to ``O(rho^2)``), so
    ``t(rho) = T - rho^2/2 - a rho^4 - b rho^6 - ...``: :func:`shrinking_time`
    with ``rate = 2``.

    Parameters
    ----------
    t_levels, levels : (k,) float arrays
        Times at which ``rho`` reached ``levels`` (decreasing), ``k >= 4``.

    Returns
    -------
    T, error : float
    """
    return shrinking_time(t_levels, levels, rate=2.0)


def extinction_time(t_levels, levels):
    """Extinction time of a closed surface of revolution shrinking to a round point.

    Its area radius ``rho = sqrt(A / (4 pi))`` obeys ``d(rho^2)/dt = -4`` on a
    round sphere (``dA/dt = -int H^2 = -16 pi``, ``H`` the sum of the principal
    curvatures), and the surface becomes round as it vanishes (Huisken 1984), so
    ``t(rho) = T - rho^2/4 - a rho^4 - b rho^6 - ...``: :func:`shrinking_time`
    with ``rate = 4``. Exact for a sphere: ``a = b = 0``, ``T = R^2 / 4``.

    Parameters
    ----------
    t_levels, levels : (k,) float arrays
        Times at which ``rho`` reached ``levels`` (decreasing), ``k >= 4``.

    Returns
    -------
    T, error : float
    """
    return shrinking_time(t_levels, levels, rate=4.0)


def shrinking_time(t_levels, levels, rate):
    """The time ``T`` at which a radius ``rho`` with ``d(rho^2)/dt -> -rate`` vanishes.

    Least squares for ``T, a, b`` in ``t(rho) = T - rho^2 / rate - a rho^4 - b rho^6``
    on the given levels.

    Parameters
    ----------
    t_levels, levels : (k,) float arrays
        Times at which ``rho`` reached ``levels`` (decreasing), ``k >= 4``.
    rate : float
        The limit of ``-d(rho^2)/dt`` (2: a tube's cross-section radius; 4: the
        area radius of a shrinking sphere).

    Returns
    -------
    T, error : float
        ``T`` from the fit with ``rho^4, rho^6``; the error estimate is the
        largest change of ``T`` when the ``rho^6`` term or the largest level is
        dropped.
    """
    t, r = np.asarray(t_levels, float), np.asarray(levels, float)
    if len(t) < 4 or len(t) != len(r):
        raise ValueError(f"need at least 4 levels with their times, got {len(r)} levels "
                         f"and {len(t)} times")

    def fit(sel, powers):
        A = np.column_stack([np.ones(sel.sum())] + [-r[sel] ** p for p in powers])
        return np.linalg.lstsq(A, t[sel] + r[sel] ** 2 / rate, rcond=None)[0][0]

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
