"""The shared driver (mcfbench/running/driver.py) on a flow whose answer is known exactly.

``Decay`` is implicit Euler for ``x' = -x`` on n points: each step solves
``(1 + tau) x^n = x^{n-1}``, so ``x^n = x^0 / (1 + tau)^n``.
"""

import numpy as np
import pytest
import scipy.sparse as sp

from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.flow import SchemeFlow
from mcfbench.running.schemes import SCHEMES
from mcfbench.running.solver import Solver


class Decay:
    """A minimal :class:`mcfbench.running.flow.SchemeFlow`: implicit Euler for x' = -x."""

    def __init__(self, vertices, faces, tau, *, defect_at=None, status="t_escaped"):
        self.tau, self.n = float(tau), 0
        self._X = np.ascontiguousarray(np.asarray(vertices, float).T)
        self._faces = np.asarray(faces)
        self.defect_at, self.status = defect_at, status

    state = X = property(lambda self: self._X)
    vertices = property(lambda self: self._X.T)
    faces = property(lambda self: self._faces)
    l2_weights = property(lambda self: np.ones(self._X.shape[1]))

    def system(self, at, base, dt):
        return (sp.identity(self._X.shape[1], format="csr") * (1.0 + dt),
                self._X if base is None else base)

    def advance(self, X):
        self._X, self.n = X, self.n + 1

    def defects(self):
        if self.defect_at is not None and self.n >= self.defect_at:
            return [(self.status, f"point 0 at {self._X[0, 0]:.3f}")]
        return []

    def frame(self):
        return {"vertices": self._X.T.copy()}


V0 = np.arange(12.0).reshape(4, 3) + 1.0
V0[:, 2] **= 2        # not collinear: the two triangles have an area, which shrinks
FACES = np.array([[0, 1, 2], [0, 2, 3]])


def test_decay_follows_the_contract():
    assert isinstance(Decay(V0, FACES, 0.1), SchemeFlow)


def test_states_and_frames_are_exact():
    traj = simulate(Decay(V0, FACES, 0.1), 7, save_every=3, solver=Solver(rtol=1e-14))
    np.testing.assert_array_equal(traj.steps, [0, 3, 6, 7])
    np.testing.assert_allclose(traj.t, [0.0, 0.3, 0.6, 0.7])
    expected = V0[None] / 1.1 ** traj.steps[:, None, None]
    np.testing.assert_allclose(traj.frames["vertices"], expected, rtol=1e-13)
    assert traj.status == "ok" and traj.message == "" and traj.failed_step == -1
    assert traj.steps_done == 7 and len(traj.iterations) == 7 and np.isnan(traj.t_failed)


def test_save_every_zero_keeps_first_and_last():
    traj = simulate(Decay(V0, FACES, 0.1), 5, save_every=0)
    np.testing.assert_array_equal(traj.steps, [0, 5])


def test_observers_see_every_level_in_order():
    seen = []
    simulate(Decay(V0, FACES, 0.1), 3, observers=[lambda f: seen.append(("a", f.n)),
                                                  lambda f: seen.append(("b", f.n))])
    assert seen == [("a", 0), ("b", 0), ("a", 1), ("b", 1), ("a", 2), ("b", 2),
                    ("a", 3), ("b", 3)]


def test_defect_stops_the_run_and_keeps_the_invalid_state():
    traj = simulate(Decay(V0, FACES, 0.5, defect_at=2), 6)
    assert traj.status == "t_escaped" and traj.failed_step == 2
    assert traj.message == "t_escaped at step 2 (t = 1): point 0 at 0.444"
    assert traj.steps_done == 2 and traj.steps[-1] == 2 and traj.t_failed == 1.0


def test_defect_recorded_lets_the_run_go_on_but_not_pass_as_ok():
    traj = simulate(Decay(V0, FACES, 0.5, defect_at=2, status="inverted"), 6,
                    on_defect="record")
    assert traj.status == "inverted" and traj.failed_step == 2 and traj.steps_done == 6
    assert traj.defects == [{"status": "inverted", "step": 2, "time": 1.0,
                             "detail": "point 0 at 0.444"}]
    assert traj.message.startswith("inverted at step 2 (t = 1): ")


def test_defect_of_the_initial_state_is_reported_at_step_0():
    traj = simulate(Decay(V0, FACES, 0.5, defect_at=0, status="degenerated"), 4)
    assert traj.status == "degenerated" and traj.failed_step == 0 and traj.steps_done == 0
    np.testing.assert_array_equal(traj.steps, [0])


def test_solver_failure_keeps_the_last_valid_state():
    flow = Decay(V0, FACES, 0.5)
    traj = simulate(flow, 4, solver=Solver(rtol=1e-12, maxiter=1))
    # the identity-times-1.5 system converges in one iteration from any x0
    assert traj.status == "ok"
    flow = Decay(V0, FACES, 0.5)
    flow.system = lambda at, base, dt: (sp.csr_matrix((12, 12)), flow._X)
    traj = simulate(flow, 4)
    assert traj.status.startswith("solver_") and traj.failed_step == 1
    assert traj.message.startswith(f"{traj.status} at step 1 (t = 0.5): ")
    np.testing.assert_array_equal(traj.frames["vertices"][-1], V0)


class FailsAt:
    """The default solver, but its ``at``-th solve fails (a zero matrix: a breakdown)."""

    def __init__(self, at):
        self.at, self.calls, self.solver = at, 0, Solver(rtol=1e-14)

    def __call__(self, A, b, x0):
        self.calls += 1
        return self.solver(sp.csr_matrix(A.shape) if self.calls == self.at else A, b, x0)


@pytest.mark.parametrize("save_every", [0, 1])
def test_a_run_continued_after_a_solver_failure_is_the_run_without_it(save_every):
    """BDF2 (its past state needed) fails at step 3 of 6; continued from step 2 with
    another solver, the whole run's frames, steps and iterations are those of the
    run that did not fail: BDF2's ``x^n`` of ``x' = -x``, ``(1 + 2 tau / 3) x^{n+1}
    = (4 x^n - x^{n-1}) / 3``, to round-off. Continued with the history lost (an
    Euler step at step 3) it is off by 30 %."""
    whole = simulate(Decay(V0, FACES, 0.5), 6, integrator="bdf2", save_every=save_every,
                     solver=Solver(rtol=1e-14))
    failed = simulate(Decay(V0, FACES, 0.5), 6, integrator="bdf2", save_every=save_every,
                      solver=FailsAt(3))
    assert failed.status == "solver_breakdown" and failed.steps_done == 2
    assert failed.steps[-1] == 2 and failed.continue_with is not None
    continued = failed.continue_with(Solver("direct"))
    assert continued.status == "ok" and continued.defects == [] and continued.steps_done == 6
    assert continued.continue_with is None
    np.testing.assert_array_equal(continued.steps, whole.steps)
    np.testing.assert_allclose(continued.frames["vertices"], whole.frames["vertices"],
                               rtol=1e-13)
    np.testing.assert_array_equal(continued.iterations[:2], whole.iterations[:2])
    np.testing.assert_array_equal(continued.iterations[2:], 0)      # direct: 0
    assert failed.steps[-1] == 2 and failed.status == "solver_breakdown"   # unchanged
    with pytest.raises(ValueError, match="only once"):
        failed.continue_with(Solver("direct"))


def test_only_a_solver_failure_can_be_continued():
    assert simulate(Decay(V0, FACES, 0.5), 3).continue_with is None
    assert simulate(Decay(V0, FACES, 0.5, defect_at=2), 3).continue_with is None


def test_until_ends_the_run_at_a_steady_state():
    traj = simulate(Decay(V0, FACES, 0.5), 50, until=lambda f: f.X[0, 0] < 0.1)
    assert traj.status == "ok" and traj.steps_done == 6      # 1 / 1.5^6 = 0.088
    assert traj.steps[-1] == 6


@pytest.mark.parametrize("kwargs, message", [
    (dict(steps=-1), "steps must be a whole number"),
    (dict(steps=1.5), "steps must be a whole number"),
    (dict(steps=2, save_every=-2), "save_every must be a whole number"),
    (dict(steps=2, on_defect="ignore"), "unknown on_defect 'ignore'"),
])
def test_bad_arguments_are_named(kwargs, message):
    with pytest.raises(ValueError, match=message):
        simulate(Decay(V0, FACES, 0.1), **kwargs)


def test_every_run_builds_its_own_kept_factor(monkeypatch):
    """A solver that keeps an ILU factor across solves keeps it for one run: a second
    run with the same solver (a timed repeat after the first execution or a warm-up)
    factors again inside its own steps, and the caller's solver keeps nothing."""
    from mcfbench.running import solver as solver_module

    factored = []
    ilu_factor = solver_module.ilu_factor
    monkeypatch.setattr(solver_module, "ilu_factor",
                        lambda A, *args: factored.append(A.shape) or ilu_factor(A, *args))
    solver = Solver("kept-ilu-bicgstab", rtol=1e-12)
    first = simulate(Decay(V0, FACES, 0.1), 3, solver=solver)
    assert factored == [(4, 4)]                   # once for the run's three solves
    again = simulate(Decay(V0, FACES, 0.1), 3, solver=solver)
    assert factored == [(4, 4), (4, 4)] and solver._kept == {}
    assert np.array_equal(first.frames["vertices"], again.frames["vertices"])


def test_a_run_that_ends_ok_has_no_extinction():
    V, F = icosphere(1)
    traj = simulate(SCHEMES["cotan"].make(V, F, 0.01), 5, save_every=0)
    assert traj.ok and traj.events == [] and np.isnan(traj.extinction_time)
    assert traj.flow.n == 5 and np.array_equal(traj.faces, F)
    ended = simulate(SCHEMES["cotan"].make(V, F, 0.01), 40, save_every=0)
    assert ended.status == "extinct" and ended.extinction_time == \
        ended.events[-1]["extinction_time"] > ended.t_failed


def test_an_invalid_state_is_never_the_flows_end():
    """The icosphere under x' = -x, tau = 0.5: round, its area 0.198 of the initial one at
    step 2 with A / (16 pi) = 0.046 < 2 tau left: ``extinct`` there, unless the state has
    a defect of its own, which is the run's status (stop and record modes alike)."""
    V, F = icosphere(1)
    assert simulate(Decay(V, F, 0.5), 6).status == "extinct"
    stopped = simulate(Decay(V, F, 0.5, defect_at=2), 6)
    assert stopped.status == "t_escaped" and stopped.events == [] and stopped.steps_done == 2
    recorded = simulate(Decay(V, F, 0.5, defect_at=2), 6, on_defect="record")
    assert recorded.status == "t_escaped" and recorded.steps_done == 2
    assert [d["status"] for d in recorded.defects] == ["t_escaped", "extinct"]
    # its last state: extinct only once collapsed, whatever its time left
    assert simulate(Decay(V, F, 0.5), 2).status == "ok"
