"""The locality order at a run's intake (mcfbench.running.locality): a permutation that
narrows the adjacency's band, undone exactly on everything a run returns."""

import numpy as np
import pytest
from conftest import FailsAt

from mcfbench.geometry.measures import vertex_components
from mcfbench.geometry.spheres import icosphere
from mcfbench.running import locality
from mcfbench.running.locality import InputOrder, locality_order
from mcfbench.running.run import run
from mcfbench.running.schemes import get_scheme
from mcfbench.running.solver import Solver


def _bandwidth(F):
    return int(np.abs(F[:, [0, 1, 2]] - F[:, [1, 2, 0]]).max())


def test_the_order_is_a_renumbering_with_a_narrower_band_and_the_same_triangles():
    V, F = icosphere(3)
    order = locality_order(V, F, min_vertices=0)
    assert np.array_equal(np.sort(order.vertices), np.arange(len(V)))
    assert np.array_equal(np.sort(order.faces), np.arange(len(F)))
    V2, F2 = order.mesh(V, F)
    assert np.array_equal(V2[order.vertex_rank], V)
    # the same triangles, each with its vertices in the same cyclic order (orientation)
    assert np.array_equal(order.vertices[F2][order.face_rank], F)
    assert _bandwidth(F2) < _bandwidth(F) / 4
    # triangles sorted by their smallest new vertex
    assert np.all(np.diff(F2.min(axis=1)) >= 0) and np.ptp(F2.min(axis=1)) > len(V) / 2
    assert locality_order(V, F, min_vertices=len(V) + 1) is None


def test_components_keep_their_numbers():
    V, F = icosphere(2)
    n = len(V)
    # two spheres, the second's vertices numbered first
    V2 = np.concatenate([V + 3.0, V])
    F2 = np.concatenate([F + n, F])
    order = locality_order(V2, F2, min_vertices=0)
    labels = vertex_components(F2, 2 * n)[1]
    new_labels = vertex_components(order.mesh(V2, F2)[1], 2 * n)[1]
    assert np.array_equal(new_labels, labels[order.vertices])
    assert np.ptp(labels) == 1 and labels[0] == 0 and labels[n] == 1


def _both(monkeypatch, *args, **kwargs):
    """A run renumbered (every mesh) and one in the input's order."""
    monkeypatch.setattr(locality, "MIN_VERTICES", 0)
    ordered = run(*args, **kwargs)
    monkeypatch.setattr(locality, "MIN_VERTICES", 10 ** 12)
    return ordered, run(*args, **kwargs)


@pytest.mark.parametrize("problem", ["sphere", "catenoid"])
@pytest.mark.parametrize("scheme", ["cotan", "bgn", "ddfv-chord-carried", "kll"])
def test_a_run_is_the_same_with_and_without_the_order(monkeypatch, scheme, problem):
    from mcfbench.running.run import problem_mesh
    from mcfbench.running.problems import get_problem

    (result, traj), (plain, plain_traj) = _both(monkeypatch, scheme, problem, 2)
    V, F = problem_mesh(get_problem(problem), 2)
    assert np.array_equal(traj.frames["vertices"][0], V)         # bit for bit
    assert np.array_equal(traj.faces, F)
    assert result.status == plain.status == "ok"
    assert result.steps_done == plain.steps_done
    for key, frames in plain_traj.frames.items():
        np.testing.assert_allclose(traj.frames[key], frames, rtol=0, atol=1e-6)
    if "extra_points" in traj.frames:                 # T-vertices by the input's triangle
        np.testing.assert_allclose(traj.frames["extra_points"][0],
                                   plain_traj.frames["extra_points"][0], rtol=0, atol=1e-14)
    assert result.metrics.keys() == plain.metrics.keys()
    for name, value in plain.metrics.items():
        assert result.metrics[name] == pytest.approx(value, rel=1e-5, abs=1e-9), name
    assert abs(result.iterations - plain.iterations) <= 0.01 * plain.iterations


def test_observers_of_the_caller_see_the_input_order(monkeypatch):
    seen = {True: [], False: []}

    def watcher(ordered):
        def observer(flow):
            seen[ordered].append((flow.vertices.copy(), np.asarray(flow.X).copy(),
                                  np.asarray(flow.l2_weights).copy(), flow.frame()))
        return observer

    monkeypatch.setattr(locality, "MIN_VERTICES", 0)
    run("ddfv-chord-carried", "sphere", 2, t_final=0.05, observers=[watcher(True)])
    monkeypatch.setattr(locality, "MIN_VERTICES", 10 ** 12)
    run("ddfv-chord-carried", "sphere", 2, t_final=0.05, observers=[watcher(False)])
    assert len(seen[True]) == len(seen[False]) > 2
    for a, b in zip(seen[True], seen[False]):
        for x, y in zip(a[:3], b[:3]):
            np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(a[3]["extra_points"], b[3]["extra_points"], atol=1e-12)


class _Pushing:
    """cotan whose flow moves the vertex nearest ``point`` past the vertex nearest
    ``past`` (a neighbour), half an edge beyond it, at step ``at``: triangles fold."""

    def __init__(self, point, past, at):
        self.scheme, self.point, self.past, self.at = get_scheme("cotan"), point, past, at

    def __getattr__(self, name):
        return getattr(self.scheme, name)

    def make(self, vertices, faces, tau, **options):
        flow = self.scheme.make(vertices, faces, tau, **options)
        point, past, at = self.point, self.past, self.at

        class Pushed(type(flow)):
            def advance(self, X):
                X = np.array(X)
                if self.n + 1 == at:
                    i = np.argmin(np.linalg.norm(X.T - point, axis=1))
                    j = np.argmin(np.linalg.norm(X.T - past, axis=1))
                    X[:, i] += 1.5 * (X[:, j] - X[:, i])
                super().advance(X)

        flow.__class__ = Pushed
        return flow


def test_a_folded_triangle_is_named_in_the_input_numbering(monkeypatch):
    V, F = icosphere(2)
    V = V * (1 + 0.05 * np.sin(7 * V[:, [0]] + 3 * V[:, [1]]))    # no ties between triangles
    pushed = 100
    past = np.setdiff1d(F[(F == pushed).any(axis=1)], [pushed])[0]
    scheme = _Pushing(V[pushed], V[past], at=2)
    (result, traj), (plain, plain_traj) = _both(monkeypatch, scheme, "sphere", 2,
                                                mesh=(V, F))
    assert result.status == plain.status == "inverted"
    assert result.message == plain.message
    assert traj.defects == plain_traj.defects
    triangle = int(result.message.split("triangle ")[1].split()[0])
    assert pushed in F[triangle] or past in F[triangle]
    assert np.array_equal(traj.frames["vertices"][0], V)
    assert isinstance(traj.flow, InputOrder)
    np.testing.assert_allclose(traj.flow.vertices, plain_traj.flow.vertices, atol=1e-9)


def test_a_run_continued_with_the_robust_solver_is_given_back_in_the_input_order(
        monkeypatch):
    lu = Solver("direct", rtol=1e-12)
    monkeypatch.setattr(locality, "MIN_VERTICES", 0)
    result, traj, continued = run("ddfv-chord-carried", "sphere", 2, robust=lu,
                                  solver=FailsAt(rtol=1e-12, at=5, size=162 + 320))
    monkeypatch.setattr(locality, "MIN_VERTICES", 10 ** 12)
    whole, plain = run("ddfv-chord-carried", "sphere", 2, solver=lu)
    assert result.status == "solver_failed" and continued.status == "ok"
    assert continued.metrics["l2_error"] == pytest.approx(whole.metrics["l2_error"], rel=1e-9)
    assert isinstance(traj.flow, InputOrder)           # the continued run's last state
    np.testing.assert_allclose(traj.flow.vertices, plain.flow.vertices, atol=1e-10)
    np.testing.assert_allclose(traj.flow.frame()["extra_points"],
                               plain.flow.frame()["extra_points"], atol=1e-10)


def _two_spheres():
    """A sphere of radius 0.3 around (3, 0, 0), its vertices numbered after those of
    the unit sphere around the origin (the continuation's test, level 2)."""
    V, F = icosphere(2)
    return np.vstack([V, 0.3 * V + [3.0, 0.0, 0.0]]), np.vstack([F, F + len(V)])


def test_a_run_that_goes_on_without_a_component_is_given_back_in_the_input_order(
        monkeypatch):
    V, F = _two_spheres()
    seen = {True: [], False: []}

    def watcher(ordered):
        return lambda flow: seen[ordered].append((flow.vertices.copy(), flow.faces.copy()))

    monkeypatch.setattr(locality, "MIN_VERTICES", 0)
    result, traj = run("cotan", "sphere", 2, mesh=(V, F), tau=0.001, t_final=0.2,
                       save_every=100, observers=[watcher(True)])
    monkeypatch.setattr(locality, "MIN_VERTICES", 10 ** 12)
    plain, plain_traj = run("cotan", "sphere", 2, mesh=(V, F), tau=0.001, t_final=0.2,
                            save_every=100, observers=[watcher(False)])
    assert result.status == plain.status == "ok"
    assert [e["component"] for e in traj.events] == [1]            # the small one
    for event, same in zip(traj.events, plain_traj.events):
        assert event["step"] == same["step"]
    np.testing.assert_allclose(traj.frames["vertices"], plain_traj.frames["vertices"],
                               atol=1e-9)
    assert len(seen[True]) == len(seen[False])
    sizes = {len(v) for v, _ in seen[True]}
    assert sizes == {324, 162}                   # before and after the small one vanished
    for (v, f), (w, g) in zip(seen[True], seen[False]):
        assert np.array_equal(f, g)
        np.testing.assert_allclose(v, w, atol=1e-9)
    np.testing.assert_allclose(traj.flow.vertices, plain_traj.flow.vertices, atol=1e-9)
    assert np.array_equal(traj.flow.faces, plain_traj.flow.faces)


class _Refusing:
    """cotan refusing every mesh, naming the vertex nearest ``point``."""

    def __init__(self, point):
        self.scheme, self.point = get_scheme("cotan"), point

    def __getattr__(self, name):
        return getattr(self.scheme, name)

    def make(self, vertices, faces, tau, **options):
        i = int(np.argmin(np.linalg.norm(vertices - self.point, axis=1)))
        raise ValueError(f"vertex {i} is singular")


def test_a_scheme_refusing_the_mesh_names_the_vertex_in_the_input_numbering(monkeypatch):
    from mcfbench.running.run import framed_run

    V, F = icosphere(2)
    monkeypatch.setattr(locality, "MIN_VERTICES", 0)
    result, frames = framed_run(_Refusing(V[100]), "sphere", 2, solver=Solver())
    assert result.status == "unsupported"
    assert result.message.endswith("vertex 100 is singular"), result.message
    assert np.array_equal(frames["vertices"][0], V)
