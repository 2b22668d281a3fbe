"""The time integrators (mcfbench.running.integrators): Euler order 1, BDF2 order 2,
for the test's own toy scheme (exact answer) and for every registry scheme."""

import numpy as np
import pytest
import scipy.sparse as sp

from mcfbench.geometry.exact import eoc
from mcfbench.geometry.shapes import cylinder
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.flow import Flow
from mcfbench.running.integrators import BDF2, INTEGRATORS, Euler, get_integrator
from mcfbench.running.run import time_convergence
from mcfbench.running.schemes import SCHEMES, get_scheme
from mcfbench.running.solver import Solver

EXACT = Solver("direct")
ORDER = {"euler": (0.9, 1.15), "bdf2": (1.7, 2.4)}


class ShrinkingPoints:
    """A scheme in a few lines: every vertex follows the shrinking sphere's
    ``X' = -2 X / |X|^2`` (the mean curvature vector of the sphere through it),
    linearly implicit: ``(X - B) / dt = -2 X / |X*|^2``. No space error: a
    vertex at radius R is at ``sqrt(R^2 - 4 t)`` exactly."""

    def __init__(self, vertices, faces, tau):
        self.n, self.tau, self.faces = 0, tau, faces
        self._X = np.ascontiguousarray(np.asarray(vertices, dtype=float).T)

    state = X = property(lambda self: self._X)
    vertices = property(lambda self: self._X.T)
    l2_weights = property(lambda self: np.ones(self._X.shape[1]))
    fixed = property(lambda self: np.zeros(self._X.shape[1], bool))

    def system(self, at, base, dt):
        at = self._X if at is None else at
        return sp.diags(1.0 + 2.0 * dt / (at * at).sum(axis=0)).tocsr(), \
            self._X if base is None else base

    def advance(self, X):
        self._X, self.n = X, self.n + 1

    def defects(self):
        return []

    def frame(self):
        return {"V": self._X.T.copy()}


def radius_error(integrator, tau, t_final=0.1):
    V, F = icosphere(1)
    flow = ShrinkingPoints(V, F, tau)
    traj = simulate(flow, round(t_final / tau), solver=EXACT, integrator=integrator,
                    collapse=False)
    return np.abs(np.linalg.norm(traj.frames["V"][-1], axis=1) - np.sqrt(1 - 4 * t_final)).max()


@pytest.mark.parametrize("integrator", list(INTEGRATORS))
def test_each_integrator_has_its_order_on_the_toy_scheme(integrator):
    """Against the exact radius: EOC 1 (Euler) and 2 (BDF2, first step Euler)."""
    assert isinstance(ShrinkingPoints(*icosphere(1), 0.1), Flow)
    errors = np.array([radius_error(integrator, 0.1 / 2 ** k) for k in range(3, 8)])
    low, high = ORDER[integrator]
    orders = eoc(errors)[1:]
    assert np.all((orders > low) & (orders < high)), orders
    assert get_integrator(integrator).order == round(orders[-1])


def test_bdf2_is_more_accurate_than_euler_at_equal_step():
    assert radius_error("bdf2", 0.1 / 64) < 0.05 * radius_error("euler", 0.1 / 64)


@pytest.mark.parametrize("scheme", sorted(SCHEMES))
def test_every_scheme_has_order_1_with_euler_and_2_with_bdf2(scheme):
    """The shrinking sphere on a fixed level-1 mesh, tau halved twice, against a
    reference with tau / 8: the pointwise error, and (BGN: its points are moved
    tangentially anew at every step) the volume between the surfaces."""
    column = "volume_eoc" if scheme == "bgn" else "eoc"
    for integrator, (low, high) in ORDER.items():
        table = time_convergence(scheme, "sphere", 1, [0.005, 0.0025, 0.00125],
                                 t_final=0.02, integrator=integrator, solver=EXACT)
        orders = table[column].to_numpy()[1:]
        assert (table["status"] == "ok").all()
        assert np.all((orders > low) & (orders < high)), (integrator, orders)


def test_first_bdf2_step_is_euler_and_then_the_steps_differ():
    V, F = icosphere(1)
    flows = [get_scheme("ddfv").make(V, F, 0.01) for _ in range(2)]
    steppers = [Euler(), BDF2()]
    for flow, stepper in zip(flows, steppers):
        stepper.step(flow, EXACT)
    np.testing.assert_array_equal(flows[0].X, flows[1].X)
    for flow, stepper in zip(flows, steppers):
        stepper.step(flow, EXACT)
    assert np.abs(flows[0].X - flows[1].X).max() > 1e-6


@pytest.mark.parametrize("scheme", ["ddfv", "ddfv-eliminate", "cotan", "bgn", "cmcf"])
def test_bdf2_keeps_the_fixed_boundary_exactly(scheme):
    V, F = cylinder(8, 4)
    flow = get_scheme(scheme).make(V, F, 0.002)
    stepper = BDF2()
    for _ in range(5):
        stepper.step(flow, EXACT)
    np.testing.assert_array_equal(flow.vertices[flow.fixed], V[flow.fixed])


def test_bdf2_operators_are_taken_at_the_extrapolated_state():
    """The second BDF2 step's system is the scheme's system at 2 X^1 - X^0 with
    base (4 X^1 - X^0) / 3 and step 2 tau / 3 (I2)."""
    V, F = icosphere(1)
    flow = get_scheme("cotan").make(V, F, 0.01)
    seen = []

    def solve(A, b, x0):
        seen.append((A.toarray(), np.array(b), np.array(x0)))
        return EXACT(A, b, x0)

    stepper = BDF2()
    stepper.step(flow, solve)
    X1 = np.array(flow.state)
    stepper.step(flow, solve)
    other = get_scheme("cotan").make(V, F, 0.01)
    A, b = other.system(2 * X1 - V.T, X1 + (X1 - V.T) / 3, 2 * 0.01 / 3)
    np.testing.assert_allclose(seen[1][0], A.toarray(), rtol=1e-13, atol=1e-15)
    np.testing.assert_allclose(seen[1][1], b, rtol=1e-15)
    np.testing.assert_allclose(seen[1][2], 2 * X1 - V.T, rtol=1e-15)


def test_warm_start_previous_starts_from_the_current_state():
    V, F = icosphere(1)
    flow, starts = get_scheme("cotan").make(V, F, 0.01), []

    def solve(A, b, x0):
        starts.append(np.array(x0))
        return EXACT(A, b, x0)

    stepper = Euler(warm_start="previous")
    stepper.step(flow, solve)
    X1 = np.array(flow.state)
    stepper.step(flow, solve)
    np.testing.assert_array_equal(starts[1], X1)


@pytest.mark.parametrize("name, options, message", [
    ("bdf3", {}, "unknown integrator 'bdf3'; choose one of euler, bdf2"),
    ("euler", {"warm_start": "zero"}, "unknown warm_start 'zero'"),
])
def test_bad_integrator_settings_are_named(name, options, message):
    with pytest.raises(ValueError, match=message):
        get_integrator(name, **options)
