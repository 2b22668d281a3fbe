"""NAME+remesh: the names, the runs that remesh, their order, the state carried over;
the remesher's input and output checked before and after the compiled call (a bad mesh
is refused with its defect named, never passed to gpytoolbox's binding, which crashed
the process on such input) and its trigger."""

import numpy as np
import pytest

from mcfbench.geometry import metrics
from mcfbench.geometry.remeshing import (
    RELAPSE, RemeshRefused, RemeshTrigger, remesh, target_edge)
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.identity import run_identity
from mcfbench.running.remeshing import Remesher
from mcfbench.running.run import run
from mcfbench.running.scheme import parse_name
from mcfbench.running.schemes import SCHEMES, get_scheme, joined_name, split_name
from mcfbench.storage.frames import frame_mesh, load_frames, save_frames, surface_points


@pytest.mark.parametrize("name, parts", [
    ("cotan", ("cotan", "euler", "none")),
    ("cotan@bdf2", ("cotan", "bdf2", "none")),
    ("cotan+remesh", ("cotan", "euler", "remesh")),
    ("ddfv-chord-carried@bdf2+remesh", ("ddfv-chord-carried", "bdf2", "remesh"))])
def test_the_names_parse_and_join_back(name, parts):
    assert tuple(parse_name(name)) == parts
    assert joined_name(*split_name(name)) == name
    entry = get_scheme(name)
    assert (entry.name, entry.integrator, entry.mesh_strategy) == (name, *parts[1:])


def test_every_scheme_has_a_remeshed_variant_and_the_wrong_order_is_refused():
    for name, entry in SCHEMES.items():
        assert get_scheme(f"{name}+remesh").mesh_strategy == "remesh"
        if entry.integrates_itself:          # BGN/BDF-k: no @INTEGRATOR of it, remeshed or not
            with pytest.raises(ValueError, match="integrates in time itself"):
                get_scheme(f"{name}@bdf2+remesh")
        else:
            assert get_scheme(f"{name}@bdf2+remesh").integrator == "bdf2"
    with pytest.raises(ValueError, match="unknown mesh strategy 'remesh@bdf2'.*"
                                         "NAME@INTEGRATOR\\+STRATEGY"):
        get_scheme("cotan+remesh@bdf2")
    with pytest.raises(ValueError, match="unknown mesh strategy 'sideways'"):
        get_scheme("cotan+sideways")


def test_a_remeshed_schemes_identity_has_the_remeshing_modules_and_no_other_run_has():
    plain, remeshed = run_identity("cotan", "sphere"), run_identity("cotan+remesh", "sphere")
    assert "mcfbench/running/remeshing.py" in remeshed["modules"]
    assert "mcfbench/geometry/remeshing.py" in remeshed["modules"]
    assert not [m for m in plain["modules"] if "remeshing" in m]
    assert remeshed["scheme"]["mesh_strategy"] == "remesh"


def _orders(scheme):
    errors = []
    for level in (1, 2, 3):
        result, traj = run(scheme, "anisotropic_sphere", level)
        assert result.status == "ok", result.message
        errors.append(result.metrics["l2_error"])
        fired = [e for e in traj.events if e["event"] == "remeshed"]
        assert fired, "remeshing did not fire"
        for event in fired:     # the count kept, the surface moved by O(h^2) at most
            assert abs(event["vertices_after"] / event["vertices_before"] - 1) < 0.25
            assert event["distance"] < 0.5 * result.h ** 2
            assert not event["topology_changed"]
    return np.log2(np.array(errors[:-1]) / np.array(errors[1:]))


@pytest.mark.parametrize("scheme", ["cotan+remesh", "bgn+remesh", "ddfv-chord-bgn-carried+remesh"])
def test_the_remeshed_sphere_follows_r_of_t_at_order_two(scheme):
    """The anisotropic sphere (smallest angle 5.5, 2.8, 1.4 degrees on levels 1-3) is
    remeshed; the error against r(t) = sqrt(R^2 - 4t) still converges at order about 2
    (cotan+remesh measured 1.72, 1.93)."""
    eoc = _orders(scheme)
    assert eoc[-1] > 1.7, eoc


def _sliver_sphere():
    """A level-2 icosphere with three vertices pushed toward an opposite edge: angles
    of about 0.5 degrees."""
    V, F = icosphere(2)
    for f in F[[0, 40, 100]]:
        a, b, c = V[f]
        V[f[2]] = (a + b) / 2 + 0.01 * (c - (a + b) / 2)
    return V, F


def test_a_sliver_mesh_that_folds_without_remeshing_runs_with_it():
    V, F = _sliver_sphere()
    assert metrics.min_angle(V, F) < 1.0
    h = metrics.mean_edge_length(V, F)
    tau, steps = 0.1 * h ** 2, 20          # to t = 0.18 of the extinction 0.25
    plain = get_scheme("ddfv")
    broke = simulate(plain.make(V, F, tau), steps)
    assert broke.status == "inverted", broke.status
    remeshed = get_scheme("ddfv+remesh")
    hook = Remesher(remeshed, (V, F))
    traj = simulate(remeshed.make(V, F, tau), steps, remesh=hook)
    assert traj.status == "ok", traj.message
    assert hook.calls >= 1 and traj.events[0]["min_angle_after"] > 15
    n = [len(v) for v in surface_points(traj.frames)[0]] if traj.frame_faces else [len(V)]
    assert max(abs(k / len(V) - 1) for k in n) < 0.25


def test_frames_with_changing_faces_round_trip(tmp_path):
    """A remeshed run's frames (each its own faces) save, load and read back per frame."""
    V, F = _sliver_sphere()
    scheme = get_scheme("ddfv-chord-carried+remesh")
    tau = 0.5 * metrics.mean_edge_length(V, F) ** 2
    traj = simulate(scheme.make(V, F, tau), 4, remesh=Remesher(scheme, (V, F)), save_every=1)
    assert traj.frame_faces is not None and len(traj.frame_faces[0]) != len(traj.frame_faces[-1])
    frames = {**traj.frames, "faces": traj.faces, "steps": traj.steps, "t": traj.t}
    save_frames(tmp_path / "run.npz", frames)
    back = load_frames(tmp_path / "run.npz")
    vertices, extra = surface_points(back)
    assert len(vertices) == len(extra) == len(traj.t) == 5
    for k, faces in enumerate(traj.frame_faces):
        V_k, F_k = frame_mesh(back, k)
        np.testing.assert_array_equal(F_k, faces)
        assert len(V_k) == F_k.max() + 1 and len(extra[k]) == len(F_k)  # T per triangle
    np.testing.assert_array_equal(frame_mesh(back, 0)[0], V)


def test_kll_is_reinitialised_from_the_new_mesh():
    """KLL's normal and mean curvature after a remesh are the new mesh's (its own start):
    exactly KLL's start on the new mesh; on the unit sphere H ~ 2 (the median; the discrete
    measure gives 2.8 at the 12 vertices of valence 5) and nu ~ x at every new vertex."""
    V, F = icosphere(3)
    scheme = get_scheme("kll+remesh")
    hook = Remesher(scheme, (V, F), every=1e-4)      # due at step 1
    flow = scheme.make(V, F, 1e-4)
    assert hook(flow) is None
    flow.n = 1
    new, event = hook(flow)
    assert new.n == 1 and event["why"].startswith("0.0001 time units")
    X = new.vertices
    nu, H = new.state[3:6].T, new.state[6]
    assert len(X) != len(V) or not np.allclose(X, V)
    np.testing.assert_array_equal(new.state, scheme.make(X, new.faces, 1e-4).state)
    assert abs(np.median(H * np.linalg.norm(X, axis=1)) - 2.0) < 0.1   # valence 5: 2.8
    np.testing.assert_allclose(np.einsum("ij,ij->i", nu, X / np.linalg.norm(X, axis=1)[:, None]),
                               1.0, atol=0.01)
    assert event["distance"] < metrics.mean_edge_length(V, F) ** 2


def test_a_final_metric_is_measured_on_the_remeshed_runs_own_mesh():
    """The problems' final observers follow the rebuilt flow (its faces, its fixed)."""
    from mcfbench.running.observers import METRICS

    V, F = _sliver_sphere()
    scheme = get_scheme("cotan+remesh")
    shape = METRICS["shape"](None)
    traj = simulate(scheme.make(V, F, 1e-3), 3, remesh=Remesher(scheme, (V, F)),
                    observers=[shape])
    assert traj.frame_faces is not None
    last_V, last_F = traj.flow.vertices, traj.flow.faces
    assert shape.result() == {"volume": metrics.volume(last_V, last_F),
                              "area": metrics.area(last_V, last_F)}


def _nan(V, F):
    V = V.copy()
    V[7] = np.nan
    return V, F


def _duplicate(V, F):
    return V, np.r_[F, F[3:4, [1, 2, 0]]]


def _zero_area(V, F):
    V = V.copy()
    a, b, c = F[5]
    V[c] = (V[a] + V[b]) / 2
    return V, F


def _unreferenced(V, F):
    return np.r_[V, [[2.0, 0.0, 0.0]]], F


def _bowtie(V, F):
    """Two spheres sharing one vertex: a non-manifold vertex."""
    W = V + [3.0, 0.0, 0.0]
    W[0] = V[0]
    G = F + len(V)
    G[G == len(V)] = 0
    keep = np.r_[np.arange(len(V)), np.arange(1, len(V)) + len(V)]
    renumber = np.full(2 * len(V), -1)
    renumber[keep] = np.arange(len(keep))
    return np.r_[V, W][keep], renumber[np.r_[F, G]]


@pytest.mark.parametrize("defect, kind", [
    (_nan, "non-finite coordinate"), (_duplicate, "duplicate triangle"),
    (_zero_area, "zero-area triangle"), (_unreferenced, "unreferenced vertex"),
    (_bowtie, "non-manifold vertex")])
def test_a_bad_input_is_refused_naming_its_defect(defect, kind, monkeypatch):
    import gpytoolbox

    def never(*args, **kwargs):
        raise AssertionError("the compiled remesher was called on a bad mesh")

    monkeypatch.setattr(gpytoolbox, "remesh_botsch", never)
    V, F = defect(*icosphere(2))
    with pytest.raises(RemeshRefused, match=f"refused its input \\({kind}\\)"):
        remesh(V, F, 0.2)


@pytest.mark.parametrize("h, passes", [(0.0, 3), (np.nan, 3), (0.2, 0), (0.2, 1.5)])
def test_a_bad_length_or_pass_count_is_refused(h, passes):
    with pytest.raises(RemeshRefused, match="edge length > 0 and whole passes >= 1"):
        remesh(*icosphere(2), h, passes)


def test_a_bad_output_is_refused(monkeypatch):
    import gpytoolbox

    V, F = icosphere(2)
    monkeypatch.setattr(gpytoolbox, "remesh_botsch", lambda *a, **k: (V, np.r_[F, F[:1]]))
    with pytest.raises(RemeshRefused, match="output is not a valid surface \\(duplicate"):
        remesh(V, F, 0.2)


def test_a_good_mesh_is_remeshed_to_about_its_vertex_count():
    V, F = icosphere(3)
    U, G = remesh(V, F, target_edge(V, F))
    assert abs(len(U) / len(V) - 1) < 0.25
    assert U.dtype == np.float64 and G.dtype == np.int64
    assert metrics.min_angle(U, G) > 20


def test_a_run_whose_state_the_remesher_refuses_ends_degenerated_naming_it():
    """A state the flow produced with a NaN coordinate (here planted) reaches the hook:
    the run ends ``degenerated`` at that step with the remesher's sentence."""
    V, F = icosphere(2)
    scheme = get_scheme("cotan+remesh")
    tau = 0.1 * metrics.mean_edge_length(V, F) ** 2
    hook = Remesher(scheme, (V, F), every=tau)
    flow = scheme.make(V, F, tau)

    class Planted:
        before_checks, kept = hook.before_checks, hook.kept

        def __call__(self, flow):
            if flow.n == 2:
                return hook(Bad(flow))
            return hook(flow)

    class Bad:
        def __init__(self, flow):
            self.flow = flow

        def __getattr__(self, name):
            value = getattr(self.flow, name)
            if name == "vertices":
                value = value.copy()
                value[4] = np.inf
            return value

    traj = simulate(flow, 5, remesh=Planted())
    assert traj.status == "degenerated" and traj.failed_step == 2, traj.message
    assert "refused its input (non-finite coordinate)" in traj.message
    assert hook.calls == 1           # step 1 (every tau) remeshed, step 2 refused


def test_a_remesh_that_could_not_lift_the_angle_waits_until_the_angle_halves():
    """After a remesh that left 4 degrees (< 10), the trigger waits for 2 degrees; after
    one that left 30, it is back at 10 (mcfbench.geometry.remeshing.RELAPSE)."""
    def mesh(angle):
        """A right-angled triangle whose smallest angle is ``angle`` degrees."""
        return (np.array([[0.0, 0, 0], [1, 0, 0], [1, np.tan(np.radians(angle)), 0]]),
                np.array([[0, 1, 2]]))

    trigger = RemeshTrigger(10.0)
    assert "smallest angle 5 degrees < 10" in trigger(*mesh(5.0), 0.0)
    trigger.done(0.0, 4.0)
    assert trigger.threshold == RELAPSE * 4.0 == 2.0
    assert trigger(*mesh(3.0), 0.1) is None
    assert "< 2" in trigger(*mesh(1.9), 0.2)
    trigger.done(0.2, 30.0)
    assert trigger.threshold == 10.0 and "< 10" in trigger(*mesh(9.0), 0.3)
