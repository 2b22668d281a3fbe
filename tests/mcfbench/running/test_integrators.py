"""The time integrators (mcfbench.running.integrators): Euler order 1, BDF2 order 2,
BDF3 order 3, for the test's own toy scheme (exact answer) and for the registry's
schemes."""

from fractions import Fraction

import numpy as np
import pytest
import scipy.sparse as sp

from mcfbench.geometry.exact import eoc
from mcfbench.geometry.shapes import cylinder
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.flow import SchemeFlow
from mcfbench.running.integrators import (BDF2, BDF3, INTEGRATORS, Euler, bdf_formula,
                                          get_integrator)
from mcfbench.running.run import time_convergence
from mcfbench.running.schemes import SCHEMES, get_scheme
from mcfbench.running.solver import Solver

pytestmark = pytest.mark.usefixtures("timed_once")      # what the runs compute, not their time

EXACT = Solver("direct")
ORDER = {"euler": (0.9, 1.15), "bdf2": (1.7, 2.4), "bdf3": (2.8, 3.2)}


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
        return {"vertices": self._X.T.copy()}


def radius_error(integrator, tau, t_final=0.1):
    V, F = icosphere(1)
    flow = ShrinkingPoints(V, F, tau)
    traj = simulate(flow, round(t_final / tau), solver=EXACT, integrator=integrator,
                    collapse=False)
    return np.abs(np.linalg.norm(traj.frames["vertices"][-1], axis=1) - np.sqrt(1 - 4 * t_final)).max()


@pytest.mark.parametrize("integrator", list(INTEGRATORS))
def test_each_integrator_has_its_order_on_the_toy_scheme(integrator):
    """Against the exact radius: EOC 1 (Euler), 2 (BDF2, first step Euler) and 3 (BDF3,
    extrapolated Euler and BDF2 to start; measured 2.97-3.00)."""
    assert isinstance(ShrinkingPoints(*icosphere(1), 0.1), SchemeFlow)
    errors = np.array([radius_error(integrator, 0.1 / 2 ** k) for k in range(3, 8)])
    low, high = ORDER[integrator]
    orders = eoc(errors)[1:]
    assert np.all((orders > low) & (orders < high)), orders
    assert get_integrator(integrator).order == round(orders[-1])


def test_bdf2_is_more_accurate_than_euler_at_equal_step():
    assert radius_error("bdf2", 0.1 / 64) < 0.05 * radius_error("euler", 0.1 / 64)


def test_bdf3_start_up_values_are_third_order_accurate():
    """``X^1`` (extrapolated Euler) and ``X^2`` (BDF2) have local errors O(tau^3)
    (measured 3.00 and 3.00-3.04), which an Euler first step (O(tau^2)) would not:
    with it BDF3's global EOC on the toy scheme is 2.00."""
    V, F = icosphere(1)
    errors = []
    for tau in (0.01, 0.005, 0.0025):
        flow, stepper = ShrinkingPoints(V, F, tau), BDF3()
        levels = []
        for n in (1, 2):
            stepper.step(flow, EXACT)
            levels.append(np.abs(np.linalg.norm(flow.X, axis=0) - np.sqrt(1 - 4 * n * tau)).max())
        errors.append(levels)
    orders = np.array([eoc(column)[1:] for column in np.array(errors).T])
    assert np.all((orders > 2.9) & (orders < 3.1)), orders


def test_bdf_formulas_are_the_backward_differences():
    """(I2), (I3): with ``t^{n+1} = 1``, ``t^{n-i} = -i``, ``X*`` is exact for
    polynomials of degree k - 1 and ``(X^{n+1} - B) / dt`` is ``X'(t^{n+1})`` for
    degree k."""
    assert bdf_formula(2) == ((2, -1), (1,), 3, Fraction(2, 3))
    assert bdf_formula(3) == ((3, -3, 1), (7, -2), 11, Fraction(6, 11))
    t = np.arange(0, -3, -1)                                 # t^n, t^{n-1}, t^{n-2}
    for k in (2, 3):
        e, p, q, step = bdf_formula(k)
        for degree in range(k + 1):
            X = t[:k] ** degree
            B = X[0] + sum(p_i * (X[i] - X[i + 1]) for i, p_i in enumerate(p)) / q
            assert (1 - B) / step == pytest.approx(degree), (k, degree)
            if degree < k:
                assert np.dot(e, X) == 1, (k, degree)
    with pytest.raises(ValueError, match="k = 1, 2, 3, not 4"):
        bdf_formula(4)


@pytest.mark.parametrize("integrator", ["bdf2", "bdf3"])
def test_a_fixed_point_keeps_its_coordinates_exactly(integrator):
    """Equal past levels give ``X* = B = X^n`` bitwise (any values)."""
    X = np.random.default_rng(3).normal(size=(3, 50)) * 1e3
    at, base, dt = get_integrator(integrator).evaluation(X, (X.copy(), X.copy())[
        :INTEGRATORS[integrator].order - 1], 0.1)
    np.testing.assert_array_equal(at, X)
    np.testing.assert_array_equal(base, X)


STEPPED = sorted(s for s in SCHEMES if not SCHEMES[s].integrates_itself)
"""The schemes the harness's integrators step (a scheme that integrates in time itself,
``baselines.bgn_bdf``, has its order tested with it)."""


@pytest.mark.parametrize("scheme", STEPPED)
def test_every_scheme_has_order_1_with_euler_and_2_with_bdf2(scheme):
    """The shrinking sphere on a fixed level-1 mesh, tau halved twice, against a
    reference with tau / 8: the pointwise error, and (BGN: its points are moved
    tangentially anew at every step) the volume between the surfaces."""
    column = "volume_eoc" if scheme == "bgn" else "eoc"
    for integrator in ("euler", "bdf2"):
        low, high = ORDER[integrator]
        table = time_convergence(scheme, "sphere", 1, [0.005, 0.0025, 0.00125],
                                 t_final=0.02, integrator=integrator, solver=EXACT)
        orders = table[column].to_numpy()[1:]
        assert (table["status"] == "ok").all()
        assert np.all((orders > low) & (orders < high)), (integrator, orders)


@pytest.mark.parametrize("scheme", [s for s in STEPPED if "carried" not in s])
def test_bdf3_has_order_3_on_the_sphere(scheme):
    """As above with BDF3 (measured 2.97-3.18; the asymptotic range on finer meshes in
    the docstring of mcfbench.running.integrators). The DDFV variants with carried
    T-vertices lose the pointwise order (1.1-1.4 here, volume order 2.9-3.1)."""
    column = "volume_eoc" if scheme == "bgn" else "eoc"
    table = time_convergence(scheme, "sphere", 1, [0.005, 0.0025, 0.00125], t_final=0.02,
                             integrator="bdf3", solver=EXACT)
    orders = table[column].to_numpy()[1:]
    assert (table["status"] == "ok").all()
    assert np.all((orders > 2.7) & (orders < 3.3)), orders


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


@pytest.mark.parametrize("stepper", [BDF2, BDF3])
@pytest.mark.parametrize("scheme", ["ddfv", "ddfv-eliminate", "cotan", "bgn", "cmcf"])
def test_bdf_keeps_the_fixed_boundary_exactly(scheme, stepper):
    V, F = cylinder(8, 4)
    flow = get_scheme(scheme).make(V, F, 0.002)
    stepper = stepper()
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


def test_bdf3_operators_are_taken_at_the_extrapolated_state():
    """The third BDF3 step's system is the scheme's at 3 X^2 - 3 X^1 + X^0 with base
    (18 X^2 - 9 X^1 + 2 X^0) / 11 and step 6 tau / 11 (I3), solved from X*; the first
    step solves three systems (Euler, two half steps), the second one (BDF2)."""
    V, F = icosphere(1)
    flow = get_scheme("cotan").make(V, F, 0.01)
    seen, states = [], [V.T]

    def solve(A, b, x0):
        seen.append((A.toarray(), np.array(b), np.array(x0)))
        return EXACT(A, b, x0)

    stepper = BDF3()
    for _ in range(3):
        stepper.step(flow, solve)
        states.append(np.array(flow.state))
    assert len(seen) == 5
    X0, X1, X2 = states[:3]
    other = get_scheme("cotan").make(V, F, 0.01)
    A, b = other.system(3 * X2 - 3 * X1 + X0, (18 * X2 - 9 * X1 + 2 * X0) / 11, 6 * 0.01 / 11)
    np.testing.assert_allclose(seen[4][0], A.toarray(), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(seen[4][1], b, rtol=1e-14)
    np.testing.assert_allclose(seen[4][2], 3 * X2 - 3 * X1 + X0, rtol=1e-14)


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
    ("bdf4", {}, "unknown integrator 'bdf4'; choose one of euler, bdf2, bdf3"),
    ("euler", {"warm_start": "zero"}, "unknown warm_start 'zero'"),
])
def test_bad_integrator_settings_are_named(name, options, message):
    with pytest.raises(ValueError, match=message):
        get_integrator(name, **options)


class _PlainExtrapolation(Euler):
    """Euler with ``2 X^n - X^{n-1}`` of the accepted states only (the start before the
    solve's increment was extrapolated)."""

    def step(self, flow, solve):
        info = super().step(flow, solve)
        self._moved = None
        return info


@pytest.mark.parametrize("scheme", ["ddfv-chord-carried", "ddfv-chord"])
def test_the_start_extrapolates_the_solve_of_a_flow_that_moves_its_solution(scheme):
    """Carried T-vertices are moved back after every solve: the start extrapolates the
    solve's own increment and needs far fewer iterations, the states equal to the
    solver's tolerance; a flow that takes the solution as it is steps bit for bit as
    with ``2 X^n - X^{n-1}``."""
    from mcfbench.running.problems import get_problem
    from mcfbench.running.run import problem_mesh

    catenoid = get_problem("catenoid")             # its T-vertices drift along the surface
    V, F = problem_mesh(catenoid, 1)
    solver = Solver(rtol=1e-9)
    runs, steps = [], 150
    for integrator in (Euler(), _PlainExtrapolation()):
        flow = get_scheme(scheme).make(V, F, catenoid.tau(1, (V, F)))
        iterations = sum(integrator.step(flow, solver).iterations for _ in range(steps))
        runs.append((flow.state.copy(), iterations))
    (new, fewer), (old, more) = runs
    if scheme == "ddfv-chord":
        assert np.array_equal(new, old) and fewer == more
    else:
        assert fewer < 0.75 * more
        # each solve within rtol of the other start's: their differences add up at most
        # linearly over the steps
        np.testing.assert_allclose(new, old, rtol=0, atol=steps * solver.rtol * abs(old).max())
