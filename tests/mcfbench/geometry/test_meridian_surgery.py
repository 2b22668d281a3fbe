"""The axisymmetric flow continued through the dumbbell's neck pinch
(mcfbench.geometry.meridian_surgery) and the extinction time of a vanishing
surface of revolution (mcfbench.geometry.extrapolation.extinction_time)."""

import math

import numpy as np
import pytest

from mcfbench.geometry.axisymmetric import evolve_until, initial_meridian
from mcfbench.geometry.meridians import meridian_volume
from mcfbench.geometry.extrapolation import extinction_time, observed_orders
from mcfbench.geometry.shapes import dumbbell_profile
from mcfbench.running.problems import get_problem
from mcfbench.geometry.meridian_surgery import area_radius, bulb_through_pinch, capped_bulb

RHO_LEVELS = 0.2 * 2.0 ** (-0.5 * np.arange(9))


def test_capped_bulb_keeps_the_upper_half_and_closes_it_by_a_quarter_circle():
    X, _, _ = initial_meridian("dumbbell", 801)
    k = len(X) // 2
    r_neck = X[k, 0]
    bulb = capped_bulb(X)
    upper = bulb[:, 1] >= 0.0
    # on the upper half: on the same curve r^2 = dumbbell_profile(z) to the cubic
    # spline's accuracy, far below the chords' sagitta h^2 kappa / 8 (3e-5 here)
    on = upper & (bulb[:, 1] < X[0, 1] - 0.05)     # the pole's r ~ sqrt(L - z) aside
    assert np.abs(bulb[on, 0] - np.sqrt(dumbbell_profile(bulb[on, 1]))).max() < 1e-6
    # below the neck: on the circle of the neck's radius about (0, 0)
    assert np.abs(np.hypot(*bulb[~upper].T) - r_neck).max() < 1e-12
    assert (~upper).sum() >= 2
    # both ends on the axis: the top pole and the cap's pole (0, -r_neck)
    np.testing.assert_allclose(bulb[0], (0.0, X[0, 1]), atol=0)
    np.testing.assert_allclose(bulb[-1], (0.0, -r_neck), atol=0)
    # equally spaced in arc length, as the original half
    gaps = np.hypot(*np.diff(bulb, axis=0).T)
    assert gaps.max() / gaps.min() < 1.01
    # its volume: the upper half's (down to z = 0) plus the cap's half ball, (2/3) pi r^3
    # (0.8 % of it); two polygons of one curve: their frusta agree to O(h^2), 2e-6 here
    half = meridian_volume(np.vstack([X[: k + 1], [0.0, 0.0]]))
    cap = 2.0 / 3.0 * math.pi * r_neck ** 3
    assert meridian_volume(bulb) == pytest.approx(half + cap, rel=1e-5)


def test_capped_bulb_refuses_a_meridian_without_a_neck():
    X, _, _ = initial_meridian("sphere", 41)       # r is largest at the middle node
    with pytest.raises(ValueError, match="not a neck"):
        capped_bulb(X)
    with pytest.raises(ValueError, match="odd number of nodes"):
        capped_bulb(X[:-1])


def test_extinction_time_of_a_shrinking_sphere_converges_to_r_squared_over_4():
    """The meridian solver's sphere vanishes at R^2/4 up to its space error, which
    falls at order 2 (relative 2e-4 with 81 nodes, 5e-5 with 161)."""
    radius = 0.8
    levels = radius * 0.5 * 2.0 ** (-0.5 * np.arange(6))
    errors = []
    for n in (81, 161):
        X, ends, periodic = initial_meridian("sphere", n, radius=radius)
        t_levels, _, _ = evolve_until(X, area_radius, levels, ends, periodic)
        T, fit_error = extinction_time(t_levels, levels)
        errors.append(abs(T / (radius ** 2 / 4) - 1.0))
        assert fit_error < 1e-7
    assert errors[1] < 1e-4
    assert math.log2(errors[0] / errors[1]) == pytest.approx(2.0, abs=0.3)


def test_extinction_time_fit_recovers_its_model():
    T, rho = 0.3, 0.2 * 2.0 ** (-0.5 * np.arange(7))
    t = T - rho ** 2 / 4 - 0.7 * rho ** 4 + 2.0 * rho ** 6
    found, err = extinction_time(t, rho)
    assert found == pytest.approx(T, abs=1e-13)
    with pytest.raises(ValueError, match="at least 4 levels"):
        extinction_time(t[:3], rho[:3])


def test_the_bulbs_extinction_converges_at_second_order_and_the_cut_radius_hardly_matters():
    """The dumbbell cut at neck radius delta = 0.04 and 0.02 on meridians of 101-401
    nodes: the bulbs' extinction time converges at order 2 in the mesh size, and
    halving delta moves it by far less than the coarse meshes' error (measured:
    1e-6 against 1e-5; on the reference meshes, delta = 0.01 -> 0.005 moves it by
    less than its error bar: benchmarks/axisymmetric_references.py)."""
    times = (0.12, 0.2)
    runs = {(n, d): bulb_through_pinch(n, d, times, RHO_LEVELS, rtol=1e-9)
            for n, d in ((101, 0.04), (201, 0.04), (401, 0.04), (401, 0.02))}
    T = {key: extinction_time(r["t_levels"], RHO_LEVELS)[0] for key, r in runs.items()}
    series = [T[(n, 0.04)] for n in (101, 201, 401)]
    assert observed_orders(series)[0] == pytest.approx(2.0, abs=0.3)
    # towards the dumbbell problem's reference (meshes of 1 601-12 801 nodes, cut at
    # 0.0025): each mesh a quarter of the previous one's distance from it
    reference = get_problem("dumbbell").reference["extinction_time"]
    distances = [abs(t - reference) for t in series]
    assert distances[-1] < 1e-5
    assert 3.0 < distances[-2] / distances[-1] < 5.0
    mesh_error = abs(series[-1] - series[-2])
    assert abs(T[(401, 0.04)] - T[(401, 0.02)]) < 0.3 * mesh_error
    # one bulb's volume decreases after the cut, as the flow's dV/dt = -int H < 0
    volumes = runs[(401, 0.02)]["volume"]
    assert volumes[0] > volumes[1] > 0
