"""What a run watches at every time level (mcfbench/running/monitors.py): the steady
state's test against the speed it is defined by."""

from types import SimpleNamespace

import numpy as np
import pytest

from mcfbench.geometry.metrics import max_speed
from mcfbench.running.monitors import Steady


@pytest.mark.parametrize("layout", ["C", "F"])
def test_steady_compares_exactly_the_largest_vertex_speed(layout):
    """At a threshold equal to :func:`max_speed` of the last two states the steady
    state is not reached, one ulp above it is: the monitor's buffers (the previous
    state, the work array) give the speed itself, bitwise, for the vertex schemes'
    (n, 3) views of (3, n) arrays too."""
    rng = np.random.default_rng(0)
    states = [np.asarray(rng.standard_normal((50, 3)), order=layout) for _ in range(4)]
    tau = 0.003
    for k in range(1, len(states)):
        speed = max_speed(states[k - 1], states[k], tau)
        for threshold, reached in ((speed, False), (np.nextafter(speed, np.inf), True)):
            steady = Steady(threshold)
            assert steady(SimpleNamespace(vertices=states[k - 1], tau=tau)) is False
            assert steady(SimpleNamespace(vertices=states[k], tau=tau)) is reached
            assert steady.reached is reached


def test_steady_keeps_its_own_copy_of_the_previous_state():
    """A flow that updates its vertices in place still compares two distinct states."""
    V = np.zeros((4, 3))
    flow = SimpleNamespace(vertices=V, tau=1.0)
    steady = Steady(0.5)
    steady(flow)
    V[2, 1] = 1.0                          # moved by 1 in place: speed 1 > 0.5
    assert steady(flow) is False
    assert steady(flow) is True            # not moved since
