import numpy as np
import pytest

from ddfv import Flow
from mcfbench.geometry.exact import SphereL2Error, eoc, sphere_radius, sphere_state_errors
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate


def test_l2_error_vanishes_on_the_exact_solution():
    """Rescaling each state onto r(t^n) makes every term of (3.2) zero."""
    V, F = icosphere(2)
    error = SphereL2Error()

    def exact(flow):
        r = sphere_radius(flow.n * flow.tau)
        flow._X /= np.linalg.norm(flow._X, axis=0) / r   # project onto the sphere
        flow.__dict__.pop("covolumes", None)
        error(flow)

    simulate(Flow(V, F, 0.01, t_init="exact"), 3, observers=[exact])
    assert error.levels == 3 and error.value < 1e-14


def test_l2_error_weights_are_half_the_covolumes():
    """A constant radial offset d gives sqrt(N tau d^2 area)."""
    V, F = icosphere(3)
    error = SphereL2Error()
    d, tau = 1e-3, 0.001

    class State:
        n, t = 1, 0.0

    state = State()
    state.tau = tau
    T = V[F].mean(axis=1)
    r = sphere_radius(tau)                       # the exact radius at t^1 = tau
    T = T / np.linalg.norm(T, axis=1, keepdims=True) * (r + d)
    state.X = np.concatenate([V * (r + d), T]).T
    state.l2_weights = np.full(len(V) + len(F), 0.5 * 4 * np.pi / len(V))
    state.l2_weights[len(V):] = 0.5 * 4 * np.pi / len(F)
    error(state)
    assert error.value == pytest.approx(np.sqrt(tau * d**2 * 4 * np.pi), rel=1e-10)


def test_eoc():
    np.testing.assert_allclose(eoc([1.0, 0.25, 0.0625 * 2]), [np.nan, 2.0, 1.0])
    assert np.isnan(eoc([1.0])).all()


def test_sphere_radius():
    assert sphere_radius(0.0, 2.0) == 2.0
    assert sphere_radius(0.25) == 0.0


def test_l2_error_kernel_matches_the_numpy_formula():
    """The compiled pass of the observer is the sum of (3.2) up to round-off."""
    rng = np.random.default_rng(5)

    class State:
        n, tau = 2, 0.01

    state = State()
    state.X = rng.standard_normal((3, 101))
    state.l2_weights = rng.random(101)
    error = SphereL2Error(radius=1.5, centre=(0.1, -0.2, 0.3))
    error(state)
    X = state.X - np.array([0.1, -0.2, 0.3])[:, None]
    dist = np.sqrt((X**2).sum(axis=0)) - sphere_radius(0.02, 1.5)
    assert error.total == pytest.approx(0.01 * np.dot(dist**2, state.l2_weights), rel=1e-13)


def test_eoc_only_between_finished_runs_one_level_apart_and_for_any_step_ratio():
    """The one EOC (3.1) of the suite: Table 3.1, the matrix, the sweeps, the time study."""
    e = [1e-2, -2.5e-3, 6.25e-4, 1e-4, 2.5e-5]          # signed errors: |e| counts
    np.testing.assert_allclose(eoc(e, levels=[1, 2, 3, 5, 6], ok=[1, 1, 0, 1, 1]),
                               [np.nan, 2.0, np.nan, np.nan, 2.0])
    assert np.isnan(eoc([1e-2, 0.0])).all()                      # an exact zero: no order
    np.testing.assert_allclose(eoc([1e-2, 1e-3], sizes=[0.3, 0.03]), [np.nan, 1.0])


def test_sphere_state_errors_vanish_on_the_exact_state_and_measure_offsets():
    """The exact sphere at ``t`` with its outer normals and ``H = 2 / r``: zero; a radial
    offset ``d``, a normal and a curvature off by constants: ``sqrt(area) x`` those."""
    V, F = icosphere(3)
    t, r = 0.05, float(sphere_radius(0.05))
    w = np.full(len(V), 4.0 / len(V))                       # weights summing to 4
    exact = sphere_state_errors(r * V, w, t, normals=V, curvature=np.full(len(V), 2 / r))
    assert max(exact.values()) < 1e-14
    shifted = sphere_state_errors((r + 1e-3) * V, w, t, normals=-V,
                                  curvature=np.full(len(V), 2 / r + 0.1))
    assert shifted == pytest.approx({"position": 2e-3, "normal": 4.0, "curvature": 0.2})
    assert set(sphere_state_errors(V, w, 0.0)) == {"position"}
