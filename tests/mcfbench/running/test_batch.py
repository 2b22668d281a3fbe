"""Runs of the run store (mcfbench.running.batch): a spec's run is the study's run,
a batch computes what the store lacks and reads the rest."""

import json
import os

import numpy as np
import pytest

from mcfbench.running.batch import run_batch, spec_of
from mcfbench.running.run import run
from mcfbench.storage import run_store
from mcfbench.storage.frames import load_frames

pytestmark = pytest.mark.usefixtures("timed_once")

SOLVER = {"method": "bicgstab", "rtol": 1e-9, "maxiter": 1000}


def test_a_level_rule_spec_resolves_the_time_step_and_a_mesh_rule_keeps_its_inputs():
    spec = spec_of("cotan", "sphere", 3, solver=SOLVER)
    assert (spec.tau, spec.t_final, spec.tau_edge, spec.steps) == (0.0025, 0.08, None, None)
    from mcfbench.running.problems import PROBLEMS

    name = next(n for n, p in PROBLEMS.items() if p.tau_rule == "mesh")
    mesh = spec_of("cotan", name, 1, solver=SOLVER)
    assert mesh.tau is None and mesh.t_final is None and mesh.steps > 0 and mesh.tau_edge > 0


def test_a_batch_computes_what_the_store_lacks_and_reads_the_rest(tmp_path):
    root = str(tmp_path / "runs")
    specs = [spec_of(s, "sphere", 1, solver=SOLVER) for s in ("cotan", "ddfv")]
    entries = [{"spec": s.to_dict(), "code": "c0de"} for s in specs]
    first = run_batch(entries[:1], tmp_path / "a.json", root=root)
    assert [r["computed"] for r in first["runs"]] == [True]
    record = run_store.record_path(specs[0], root)
    stamp = os.stat(record).st_mtime_ns, open(record).read()
    second = run_batch(entries, tmp_path / "b.json", root=root)
    assert [r["computed"] for r in second["runs"]] == [False, True]
    assert (os.stat(record).st_mtime_ns, open(record).read()) == stamp     # untouched
    assert json.loads((tmp_path / "b.json").read_text())["runs"][1]["key"] == specs[1].key
    # another code digest: computed again
    third = run_batch([{**entries[0], "code": "new"}], tmp_path / "c.json", root=root)
    assert [r["computed"] for r in third["runs"]] == [True]
    assert run_store.read_run(specs[0], "new", root)["settings"]["code"] == "new"


def test_a_stored_run_is_the_studies_run_with_its_final_weights(tmp_path):
    """The record's numbers are run()'s (Table 3.1's job ran run(); the matrix's
    framed_run with the robust continuation, unused on the sphere); the frames carry
    the final state's quadrature weights."""
    root = str(tmp_path)
    spec = spec_of("ddfv", "sphere", 2, solver=SOLVER)
    run_batch([{"spec": spec.to_dict(), "code": "c"}], tmp_path / "m.json", root=root)
    record = run_store.read_run(spec, "c", root)
    result, traj = run("ddfv", "sphere", 2)
    for key in ("l2_error", "iterations", "nV", "N", "status", "t_min_barycentric"):
        assert record[key] == result.to_dict()[key], key
    frames = load_frames(run_store.frames_path(spec, root))
    assert record["robust_status"] == "" and record["metric_names"] == ["l2_error"]
    np.testing.assert_array_equal(frames["vertices"][-1], traj.frames["vertices"][-1])
    weights = frames["l2_weights"]
    assert weights.shape == (482,) and np.all(weights > 0)
    radius = np.sqrt(1 - 4 * 0.08)
    assert weights.sum() == pytest.approx(4 * np.pi * radius ** 2, rel=0.02)


def test_each_scheme_of_a_batch_is_warmed_up_before_its_first_run_is_timed(tmp_path,
                                                                         monkeypatch):
    """One process, several schemes (a batch job): each scheme's first run is warmed up
    before the clock starts, also after another scheme ran first."""
    from mcfbench.running import run as run_module

    timed, timed_run = [], run_module._timed_run

    def spy(scheme, problem, mesh, tau, steps, **kwargs):
        timed.append((scheme.name, steps))
        return timed_run(scheme, problem, mesh, tau, steps, **kwargs)

    monkeypatch.setattr(run_module, "_warmed", set())       # as a fresh process
    monkeypatch.setattr(run_module, "_timed_run", spy)
    specs = [spec_of(s, "sphere", 1, solver=SOLVER) for s in ("cotan", "bgn")]
    run_batch([{"spec": s.to_dict(), "code": "c"} for s in specs], tmp_path / "m.json",
              tmp_path / "batch.log", root=str(tmp_path))
    assert [call for k, call in enumerate(timed) if k == 0 or timed[k - 1] != call] == \
        [("cotan", run_module.WARM_UP_STEPS), ("cotan", 2),
         ("bgn", run_module.WARM_UP_STEPS), ("bgn", 2)]
    text = (tmp_path / "batch.log").read_text()
    assert "cotan on sphere level 1" in text and "bgn on sphere level 1" in text


def test_a_remeshed_run_of_a_user_mesh_is_stored_with_its_frames_own_faces(tmp_path):
    """A run that remeshes (cotan+remesh on a sphere with 0.5-degree slivers, a mesh
    file) is stored like any: its frames carry each frame's faces, and no final
    quadrature weights (the time study's, of a run on one mesh: its last state is on
    another). The batch job once failed here, building those weights on the input's
    faces."""
    import igl

    from mcfbench.running.batch import compute, mesh_spec
    from mcfbench.storage.frames import frame_mesh
    from mcfbench.storage.run_store import mesh_sha256
    from test_remeshing import _sliver_sphere

    V, F = _sliver_sphere()
    path = tmp_path / "slivers.obj"
    igl.write_triangle_mesh(str(path), V, F)
    root = str(tmp_path / "runs")
    spec = mesh_spec("cotan+remesh", str(path), mesh_sha256(path), tau_edge=0.1, steps=10,
                     solver={"method": "direct", "rtol": 1e-9, "maxiter": 1000}, frames=10)
    record = compute(spec, "c0de", root)
    assert record["status"] == "ok", record["message"]
    frames = load_frames(run_store.frames_path(spec, root))
    assert "l2_weights" not in frames
    first, last = frame_mesh(frames, 0), frame_mesh(frames, -1)
    assert len(first[0]) == len(V) and not np.array_equal(first[1], last[1])


def test_a_mesh_file_is_read_once_per_process_and_again_when_it_changes(tmp_path,
                                                                         monkeypatch):
    """Every scheme of a survival batch runs on one file: it is read once (the
    specs get the same mesh, each its own copy); a file whose bytes changed is read
    again, its spec's SHA-256 checked first."""
    import igl

    from mcfbench.geometry import mesh_files
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.running import batch
    from mcfbench.running.batch import mesh_spec
    from mcfbench.storage.run_store import mesh_sha256

    reads = []
    real = mesh_files.read_mesh
    monkeypatch.setattr(mesh_files, "read_mesh", lambda p: reads.append(p) or real(p))
    V, F = icosphere(1)
    path = tmp_path / "sphere.obj"
    igl.write_triangle_mesh(str(path), V, F)

    def spec(scheme):
        return mesh_spec(scheme, str(path), mesh_sha256(path), tau_edge=0.1, steps=2,
                         solver=SOLVER, frames=2)

    (V1, F1, _), tau1, _ = batch._user_mesh(spec("cotan"))
    (V2, F2, _), tau2, _ = batch._user_mesh(spec("bgn"))
    assert len(reads) == 1 and tau1 == tau2 and V1 is not V2
    np.testing.assert_array_equal(V1, V2)
    np.testing.assert_array_equal(F1, F2)
    V1[0] = 0.0                                         # a run's copy, not the kept mesh
    assert batch._user_mesh(spec("cotan"))[0][0][0, 0] == V2[0, 0]
    old = spec("cotan")
    igl.write_triangle_mesh(str(path), 2 * V, F)
    with pytest.raises(ValueError, match="the file changed after the plan was made"):
        batch._user_mesh(old)
    (V3, _, _), tau3, _ = batch._user_mesh(spec("cotan"))
    assert len(reads) == 2 and tau3 == pytest.approx(4 * tau1)
