"""The Angenent torus: a self-shrinker of mean curvature flow, M_t = sqrt(1 - t) M_0, extinct at t = 1. Its meridian curve by shooting (the ODE of Angenent, 1992, by arclength: rho' = sin a, z' = cos a, a' = (1/rho - rho/2) cos a + (z/2) sin a, from (rho0, 0) with a = 0), the distance of points to the exact surface at any t and its area."""

import functools
import math

import numpy as np

from mcfbench.geometry.construction import quad_grid
from mcfbench.geometry.meridians import meridian_max_height

# scipy.integrate and scipy.optimize are imported on first
# use: mcfbench.geometry.surfaces imports this module for every surface, and
# importing them took 0.3-1.1 s of each pipeline job that builds another surface

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

    from scipy.integrate import solve_ivp

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
    from scipy.optimize import brentq

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

    zmax = meridian_max_height(np.column_stack([sol.sol(ss)[0], zz]))
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


@functools.cache
def default_profile():
    """:func:`angenent_profile` with the computed ``rho0``, computed once per process."""
    return angenent_profile()


def angenent_torus(n_major=48, n_minor=24):
    """The Angenent torus at ``t = 0`` as a triangle mesh (genus 1).

    Its meridian (:func:`angenent_profile`) sampled at ``n_minor`` points equally
    spaced in arc length, turned about the ``z`` axis at ``n_major`` angles;
    quads cut by alternating diagonals as :func:`mcfbench.geometry.shapes.torus`,
    vertex ``j n_major + i`` at angle ``2 pi i / n_major`` and meridian point
    ``j``, normals outwards.

    Returns
    -------
    vertices : (n_major n_minor, 3) float array
    faces : (2 n_major n_minor, 3) int64 array
    """
    if n_major < 3 or n_minor < 3:
        raise ValueError(f"need n_major, n_minor >= 3, got {n_major}, {n_minor}")
    profile = default_profile()
    rz = profile["curve"](profile["length"] * np.arange(n_minor) / n_minor)
    phi = 2.0 * np.pi * np.arange(n_major) / n_major
    rho, z = np.repeat(rz[:, 0], n_major), np.repeat(rz[:, 1], n_major)
    angle = np.tile(phi, n_minor)
    V = np.column_stack([rho * np.cos(angle), rho * np.sin(angle), z])
    # the meridian runs clockwise in (rho, z) seen with the axis on the left: reversed
    return V, quad_grid(n_major, n_minor, True, True, "alternating")[:, ::-1].copy()
