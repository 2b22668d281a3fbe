"""Tests of :mod:`mcfbench.geometry.meridians`: the quantities of a meridian polygon
against the exact ones of the sphere and the torus of revolution, at order 2 in the
node spacing."""

import math

import numpy as np

from mcfbench.geometry.meridians import measures, meridian_max_height


def _semicircle(n, R=1.0):
    """The unit sphere's meridian from pole to pole, ``n`` nodes at equal angles."""
    phi = np.linspace(-0.5 * math.pi, 0.5 * math.pi, n)
    return np.column_stack([R * np.cos(phi), R * np.sin(phi)])


def _circle(n, centre=2.0, radius=0.5, shift=0.3):
    """A torus's closed meridian, ``n`` nodes, none at the top (rotated by ``shift``)."""
    phi = 2.0 * math.pi * np.arange(n) / n + shift
    return np.column_stack([centre + radius * np.cos(phi), radius * np.sin(phi)])


def test_sphere_area_volume_and_radii_converge_at_order_two():
    errors = []
    for n in (33, 65, 129):
        m = measures(_semicircle(n))
        errors.append([abs(m["area"] - 4.0 * math.pi), abs(m["volume"] - 4.0 / 3.0 * math.pi)])
        # a node at each pole and at the equator (n odd): both exact
        assert m["max_height"] == 1.0 and abs(m["mid_radius"] - 1.0) < 1e-15
        assert math.isnan(m["min_radius"])    # no interior neck
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.05), orders


def test_torus_cross_section_tube_radius_and_height_of_a_closed_meridian():
    """The torus of revolution R = 2, r = 0.5: cross-section pi r^2, area 4 pi^2 R r,
    volume 2 pi^2 R r^2, at order 2; the largest height, by the quartic through the
    five nodes around the top, is r within 1e-5 where the highest node is 1e-3 below."""
    R, r = 2.0, 0.5
    errors = []
    for n in (32, 64, 128):
        X = _circle(n, R, r)
        m = measures(X, periodic=True)
        errors.append([abs(m["cross_section"] - math.pi * r * r),
                       abs(m["area"] - 4.0 * math.pi ** 2 * R * r),
                       abs(m["volume"] - 2.0 * math.pi ** 2 * R * r * r),
                       abs(m["tube_radius"] - r)])
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.05), orders
    X = _circle(32, R, r)
    assert r - X[:, 1].max() > 1e-3                       # the highest node is well below
    assert abs(meridian_max_height(X, periodic=True) - r) < 1e-5


def test_max_height_at_an_open_end_is_the_end_node():
    X = np.array([[0.0, 3.0], [0.5, 2.0], [1.0, 1.0], [1.5, 0.5], [2.0, 0.0]])
    assert meridian_max_height(X) == 3.0
