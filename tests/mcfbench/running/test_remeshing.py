"""NAME+remesh: the names, the runs that remesh, their order, the state carried over."""

import numpy as np
import pytest

from mcfbench.geometry import metrics
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
