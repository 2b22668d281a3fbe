"""Tests of :mod:`mcfbench.geometry.axisymmetric`: exact solutions, orders, the Angenent torus."""

import math

import numpy as np
import pytest

from mcfbench.geometry import angenent, extrapolation, meridians, metrics
from mcfbench.geometry import axisymmetric as ax
from mcfbench.geometry import axisymmetric_references as refs

RTOL = 1e-12  # Radau tolerances: time error far below the extrapolated space error


def _series(shape, ns, times, **params):
    """measures() at ``times`` for each node count in ``ns``."""
    out = []
    for n in ns:
        X, ends, per = ax.initial_meridian(shape, n, **params)
        out.append([meridians.measures(Y, per) for Y in
                    ax.evolve(X, times, ends, per, rtol=RTOL, atol=RTOL)])
    return out


@pytest.fixture(scope="module")
def sphere_runs():
    return _series("sphere", (21, 41, 81, 161, 321), [0.1])


def test_sphere_radius_follows_exact_solution(sphere_runs):
    """Extrapolated pole height, equatorial radius, area and volume at t = 0.1 against
    r = sqrt(1 - 4t) (the pole needs the h^4 log h step of the default orders)."""
    r = math.sqrt(1.0 - 0.4)
    exact = {"max_height": r, "mid_radius": r, "area": 4 * math.pi * r**2, "volume": 4 / 3 * math.pi * r**3}
    for key, value in exact.items():
        v, err, _ = extrapolation.richardson([m[0][key] for m in sphere_runs])
        assert abs(v - value) < 1e-8, key
        assert err < 1e-8, key


def test_space_order_is_two(sphere_runs):
    """The finite differences are second order: observed orders 2 +- 0.1."""
    for key in ("max_height", "area", "volume"):
        eoc = extrapolation.observed_orders([m[0][key] for m in sphere_runs])
        assert np.all(np.abs(eoc - 2.0) < 0.1), (key, eoc)


def test_crank_nicolson_is_second_order_in_time():
    """Fixed-step Crank-Nicolson against Radau on the same mesh: orders 2 +- 0.02,
    and one Richardson step in tau gains at least two digits."""
    X, ends, per = ax.initial_meridian("sphere", 41)
    ref = meridians.measures(ax.evolve(X, [0.1], ends, per, rtol=RTOL, atol=RTOL)[0])["max_height"]
    vals = [meridians.measures(ax.evolve(X, [0.1], ends, per, method="cn", tau=tau)[0])["max_height"]
            for tau in (0.01, 0.005, 0.0025)]
    eoc = extrapolation.observed_orders(vals)
    assert np.all(np.abs(eoc - 2.0) < 0.02), eoc
    assert abs(extrapolation.richardson(vals, orders=(2, 4))[0] - ref) < 1e-2 * abs(vals[-1] - ref)


def test_catenoid_neck_and_area_at_steady_state():
    """Cylinder R = 1, h = 0.5 between fixed circles: at t = 8 the extrapolated neck
    is a = 0.8483379380948 (a cosh(h/a) = R) and the area pi a (2h + a sinh(2h/a))."""
    runs = _series("cylinder", (33, 65, 129, 257), [8.0], radius=1.0, half_height=0.5)
    a = metrics.catenoid_parameter(1.0, 0.5)
    assert abs(a - 0.8483379380948415) < 1e-12
    neck = extrapolation.richardson([m[0]["mid_radius"] for m in runs])[0]
    area = extrapolation.richardson([m[0]["area"] for m in runs])[0]
    assert abs(neck - a) < 1e-8
    assert abs(area - refs.catenoid_area(1.0, 0.5)) < 1e-8


def test_hemisphere_height_decays_at_the_first_dirichlet_eigenvalue():
    runs = _series("hemisphere", (17, 33, 65), [1.5, 2.0], radius=1.0)
    rates = [math.log(m[0]["max_height"] / m[1]["max_height"]) / 0.5 for m in runs]
    assert abs(extrapolation.richardson(rates)[0] - refs.J01_SQUARED) < 1e-6


def test_angenent_rho0_by_shooting_matches_published():
    prof = angenent.angenent_profile()
    assert abs(prof["rho0"] - angenent.ANGENENT_RHO0_PUBLISHED) < 1e-10
    assert abs(prof["rho_outer"] - 3.3147) < 1e-4
    assert abs(prof["half_height"] - 0.9217) < 1e-4
    assert abs(prof["entropy"] - 1.85122) < 1e-5
    s = np.linspace(0.0, prof["length"], 37)
    assert angenent.angenent_distance(prof["curve"](s), 0.0, prof).max() < 1e-12


def test_angenent_torus_shrinks_self_similarly():
    """The flow from the Angenent torus stays at distance O(h^2) from sqrt(1 - t) M_0,
    and its extrapolated area is (1 - t) area_0."""
    prof = angenent.angenent_profile()
    t = 0.25
    dist, areas = [], []
    for n in (100, 200, 400):
        X, ends, per = ax.initial_meridian("angenent", n)
        Y = ax.evolve(X, [t], ends, per, rtol=RTOL, atol=RTOL)[0]
        dist.append(angenent.angenent_distance(Y, t, prof).max())
        areas.append(meridians.measures(Y, per)["area"])
    assert dist[-1] < 2e-4
    assert np.all(np.abs(extrapolation.observed_orders(dist) - 2.0) < 0.1)
    assert abs(extrapolation.richardson(areas)[0] / angenent.angenent_area(t, prof) - 1.0) < 1e-7


def test_pinch_time_fits_recover_synthetic_pinches():
    levels = 0.1 * 2.0 ** (-0.5 * np.arange(9))
    t = 0.3 - levels**2 / 2 - 0.7 * levels**4
    T, err = extrapolation.pinch_time_tube(t, levels)
    assert abs(T - 0.3) < 1e-12 and err < 1e-10
    from scipy.optimize import brentq

    t_neck = [brentq(lambda s, r=r: 2 * (0.3 - s) * (1 - 2 / -math.log(0.3 - s)) - r * r,
                     0.3 - 2 * r * r, 0.3 - 1e-15) for r in levels]
    T, err, _ = extrapolation.pinch_time_neck(t_neck, levels)
    assert abs(T - 0.3) < 1e-9
