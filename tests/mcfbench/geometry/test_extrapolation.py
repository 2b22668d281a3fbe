"""Richardson extrapolation, observed orders and extrapolated pinch times
(mcfbench.geometry.extrapolation) on sequences whose limit is known exactly."""

import numpy as np
import pytest

from mcfbench.geometry.extrapolation import (
    observed_orders,
    pinch_time_neck,
    pinch_time_tube,
    richardson,
)

H = 0.5 ** np.arange(5)          # h, h/2, ..., h/16


def test_richardson_removes_the_powers_it_is_told_exactly():
    """Q(h) = 3 + h^2 - 5 h^4 + 2 h^6: orders (2, 4, 6) leave 3 to rounding."""
    values = 3.0 + H ** 2 - 5.0 * H ** 4 + 2.0 * H ** 6
    value, error, table = richardson(values, orders=(2, 4, 6))
    assert value == pytest.approx(3.0, abs=1e-13)
    assert error < 1e-3 and len(table) == 4 and len(table[-1]) == 2
    # the first column, (4 Q(h/2) - Q(h)) / 3, by hand: 3 + 5/4 h^4 - 5/8 h^6
    h = H[:-1]
    np.testing.assert_allclose(table[1], 3.0 + 1.25 * h ** 4 - 0.625 * h ** 6, rtol=1e-14)


def test_richardson_with_a_log_term_needs_the_repeated_order():
    """Q(h) = 1 + h^2 + h^4 log h: the repeated 4 of the default orders removes it,
    a single 4 does not."""
    values = 1.0 + H ** 2 + H ** 4 * np.log(H)
    repeated, _, _ = richardson(values, orders=(2, 4, 4))
    single, _, _ = richardson(values[:4], orders=(2, 4, 6))
    assert abs(repeated - 1.0) < 1e-6 < abs(single - 1.0)


def test_observed_orders_of_a_pure_power():
    np.testing.assert_allclose(observed_orders(1.0 + 7.0 * H ** 3), 3.0, rtol=1e-12)


def test_pinch_time_of_a_tube_from_its_exact_law():
    """t(rho) = T - rho^2/2 - a rho^4 - b rho^6 is fitted exactly: T recovered."""
    T, a, b = 0.3, 0.7, -2.0
    rho = np.array([0.3, 0.2, 0.15, 0.1, 0.07, 0.05])
    t = T - rho ** 2 / 2 - a * rho ** 4 - b * rho ** 6
    found, error = pinch_time_tube(t, rho)
    assert found == pytest.approx(T, abs=1e-12)
    assert error > 0        # dropping the rho^6 term moves T: the estimate says so


def test_pinch_time_of_a_neck_from_its_asymptotic_law():
    """Radii on r^2 = 2 D (1 + c / L), D = T - t, L = -log D: T within 1e-9."""
    T, c = 1.25, 0.4
    D = np.geomspace(1e-2, 1e-7, 8)
    r = np.sqrt(2.0 * D * (1.0 + c / -np.log(D)))
    found, error, fits = pinch_time_neck(T - D, r)
    assert found == pytest.approx(T, abs=1e-9)
    assert error < 1e-6 and len(fits) == 6
