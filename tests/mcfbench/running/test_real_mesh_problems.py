"""The real-mesh problems (mcfbench.running.real_mesh_problems): one per committed
mesh, generated from its manifest entry and reference file; the time rule
tau_k = 0.1 h_0^2 / 4^k; the stored answers are what the reference machinery
makes of the stored runs; the stored reference surface fits its level's
regenerated faces and remakes its file byte for byte; the metric measures a
run against them (area, volume, distance)."""

import json
import math

import numpy as np
import pytest

from mcfbench.geometry.committed_meshes import mesh_manifest, real_mesh
from mcfbench.geometry.metrics import mean_edge_length
from mcfbench.geometry.surface_distance import mean_surface_distance
from mcfbench.running.problems import PROBLEMS
from mcfbench.running.real_mesh_problems import (
    RealMeshShape,
    real_mesh_problem,
    reference_path,
    reference_surface,
    surface_path,
)
from mcfbench.running.run import run
from mcfbench.running.solver import Solver
from mcfbench.running.two_scheme_references import QUANTITIES, reference_answers
from mcfbench.storage.atomic import json_value, save_npz

NAMES = sorted(mesh_manifest())


def _stored(name):
    return json.loads(reference_path(name).read_text())


def _runs(ref):
    return [{**r, **{q: [math.nan if x is None else x for x in r[q]] for q in QUANTITIES}}
            for r in ref["runs"]]


def test_every_committed_mesh_is_a_problem():
    assert {f"real_{n}" for n in NAMES} <= set(PROBLEMS)


@pytest.mark.parametrize("name", NAMES)
def test_problem_time_rule_and_levels_follow_the_reference_file(name):
    ref, problem = _stored(name), PROBLEMS[f"real_{name}"]
    V, F = problem.mesh(0)
    h0 = mean_edge_length(V, F)
    assert ref["h0"] == pytest.approx(h0, rel=1e-12)
    assert len(V) == ref["vertices"]["0"] == mesh_manifest()[name]["vertices"]
    for level in problem.levels:
        assert problem.tau(level) == pytest.approx(0.1 * h0 ** 2 / 4 ** level, rel=1e-12)
        assert problem.time_steps(problem.tau(level)) == ref["steps"] * 4 ** level
    assert 1 <= ref["steps"] <= 10 and ref["checkpoints"] == list(range(1, ref["steps"] + 1))
    assert ref["command"].endswith(f"--mesh {name}")


@pytest.mark.parametrize("name", NAMES)
def test_stored_answers_are_what_the_machinery_makes_of_the_stored_runs(name):
    ref = _stored(name)
    again = json_value(reference_answers(_runs(ref), ref["tau0"], 10))
    for key in ("steps", "checkpoints", "singularity", *QUANTITIES,
                *(f"{q}_accuracy" for q in QUANTITIES)):
        assert again[key] == ref[key], key
    for q in QUANTITIES:
        assert np.all(np.asarray(ref[f"{q}_accuracy"]) >= 0)
        assert np.all(np.asarray(ref[f"{q}_accuracy"]) < 0.05 * np.abs(ref[q]))


@pytest.mark.parametrize("name", NAMES)
def test_reference_surface_fits_its_regenerated_level_and_remakes_its_file(name, tmp_path):
    ref = _stored(name)
    surface = ref["distance_reference"]
    assert (surface["scheme"], surface["level"]) == ("cotan", ref["scheme_levels"]["cotan"][-1])
    assert surface["checkpoint"] == ref["steps"] and surface["file"] == f"{name}.npz"
    V, F = reference_surface(name, surface["level"], surface["faces_sha256"])
    assert V.shape == (surface["vertices"], 3) and surface["vertices"] == \
        ref["vertices"][str(surface["level"])]
    assert ref["length_scale"] == pytest.approx(math.sqrt(ref["area"][-1]), rel=1e-12)
    # the accuracy: the larger of the finest levels' and the schemes' distances
    assert ref["distance_accuracy"] == max(ref["distance_level_difference"],
                                           ref["distance_scheme_difference"])
    assert 0 < ref["distance_accuracy"] < 0.05
    with np.load(surface_path(name)) as stored:
        save_npz(tmp_path / "again.npz", vertices=stored["vertices"])
        assert stored["vertices"].dtype == np.float32
    assert (tmp_path / "again.npz").read_bytes() == surface_path(name).read_bytes()


def test_reference_surface_whose_level_changed_is_refused():
    surface = _stored("nut")["distance_reference"]
    with pytest.raises(ValueError, match="does not fit level 1"):
        reference_surface("nut", 1, surface["faces_sha256"])
    with pytest.raises(ValueError, match="remake it"):
        reference_surface("nut", surface["level"], "0" * 64)


def test_distance_is_measured_below_the_reference_level_only():
    """A state at t_final on the reference surface's level (as many vertices) is
    not measured (the reference does not resolve that level); one level coarser is:
    its distance to the reference surface is that of the two surfaces; a run that
    did not reach t_final has NaN."""
    ref = _stored("nut")
    level = ref["distance_reference"]["level"]
    fine = reference_surface("nut", level, ref["distance_reference"]["faces_sha256"])
    coarse = real_mesh("nut", level - 1)

    def observed(V, F):
        observer = RealMeshShape(PROBLEMS["real_nut"])

        class Flow:
            vertices, faces, tau, n = V, F, ref["tau0"], ref["steps"]
        observer(Flow)
        return observer.result()

    assert "distance_error" not in observed(*fine)
    assert observed(*coarse)["distance_error"] == pytest.approx(
        mean_surface_distance(*coarse, *fine) / ref["length_scale"], rel=1e-12)
    assert observed(*coarse)["distance_error"] > 0
    assert math.isnan(RealMeshShape(PROBLEMS["real_nut"]).result()["distance_error"])


def test_a_reference_without_a_surface_measures_no_distance():
    """A reference file without ``distance_reference`` (no surface stored): a run that
    reaches t_final gets its area and volume errors and no distance, not an error."""
    ref = {k: v for k, v in _stored("nut").items() if k != "distance_reference"}
    observer = RealMeshShape(real_mesh_problem("nut", ref))
    V, F = real_mesh("nut", 0)

    class Flow:
        vertices, faces, tau = V, F, ref["tau0"]
    for Flow.n in ref["checkpoints"]:
        observer(Flow)
    result = observer.result()
    assert "distance_error" not in result and np.isfinite(result["area_error"])


def test_metric_measures_a_run_against_the_reference():
    """cotan on level 0 of the nut: the metric's errors are the stored run's
    values at the checkpoints against the reference (worst in magnitude), and
    its final surface's mean distance to the reference surface over L."""
    ref = _stored("nut")
    result, traj = run("cotan", "real_nut", 0, solver=Solver(method="direct"))
    stored = next(r for r in ref["runs"] if (r["scheme"], r["level"]) == ("cotan", 0))
    for q in QUANTITIES:
        errors = [stored[q][j] / ref[q][j - 1] - 1 for j in ref["checkpoints"]]
        assert result.metrics[f"{q}_error"] == pytest.approx(max(errors, key=abs), rel=1e-9)
    surface = ref["distance_reference"]
    distance = mean_surface_distance(traj.frames["vertices"][-1], traj.faces, *reference_surface(
        "nut", surface["level"], surface["faces_sha256"])) / ref["length_scale"]
    assert result.metrics["distance_error"] == pytest.approx(distance, rel=1e-12)
    # level 0 is farther from the reference than the finest levels from each other
    assert ref["distance_accuracy"] < distance < 0.05


def test_mesh_whose_reference_runs_all_broke_down_before_tau0_is_no_problem(tmp_path, monkeypatch):
    from mcfbench.running import real_mesh_problems as rmp

    name = "nut"
    ref = _stored(name)
    monkeypatch.setattr(rmp, "REFERENCE_DIR", tmp_path)
    (tmp_path / f"{name}.json").write_text(json.dumps(ref))
    assert f"real_{name}" in rmp.real_mesh_problems()
    (tmp_path / f"{name}.json").write_text(json.dumps({**ref, "steps": 0, "checkpoints": []}))
    assert f"real_{name}" not in rmp.real_mesh_problems()
    assert rmp.real_mesh_problems().keys() == set()    # no other reference in the folder
