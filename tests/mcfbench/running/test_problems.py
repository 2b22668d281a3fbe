"""The problem registry (mcfbench/running/problems.py): meshes, time rules, metrics."""

import numpy as np
import pytest

from mcfbench.geometry.committed_meshes import mesh_manifest
from mcfbench.geometry.mesh import summarize
from mcfbench.geometry.metrics import catenoid_parameter
from mcfbench.running.problems import PROBLEMS, Problem, get_problem, time_steps
from mcfbench.running.run import run
from mcfbench.running.schemes import SCHEMES
from mcfbench.storage.statuses import STATUSES

CLOSED = {"sphere": 0, "torus": 1, "dumbbell": 0, "dumbbell_through_pinch": 0, "perturbed_sphere": 0, "remeshed_sphere": 0,
          "anisotropic_sphere": 0, "blobby": 0, "marching_torus": 1, "angenent": 1,
          **{f"real_{name}": entry["genus"] for name, entry in mesh_manifest().items()}}
OPEN = {"catenoid": 2, "hemisphere": 1, "flat_patch": 1, "enneper": 1}


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_every_problem_has_a_valid_mesh_and_time_rule(name):
    problem = get_problem(name)
    level = problem.levels[0]
    V, F = problem.mesh(level)
    summary = summarize(V, F)
    assert summary.components == 1
    if name in CLOSED:
        assert summary.boundary_loops == 0 and summary.genus == (CLOSED[name],)
    else:
        assert summary.boundary_loops == OPEN[name]
    tau = problem.tau(level, (V, F))
    assert tau > 0 and problem.time_steps(tau) >= 1
    assert len(problem.observers()) == len(problem.metrics)
    assert problem.label and problem.exact and problem.description


def test_refinement_series_halves_h_and_quarters_tau():
    from mcfbench.geometry.metrics import mean_edge_length

    for name in ("sphere", "catenoid", "hemisphere", "torus"):
        problem = get_problem(name)
        h = [mean_edge_length(*problem.mesh(k)) for k in problem.levels[:3]]
        np.testing.assert_allclose(np.array(h[:-1]) / h[1:], 2.0, rtol=0.08, err_msg=name)
        assert problem.tau(2) == problem.tau(1) / 4


def test_catenoid_metric_vanishes_on_the_catenoid():
    """The metric of the final state: a cylinder moved onto r = a cosh(z/a) has no error."""
    problem = get_problem("catenoid")
    V, F = problem.mesh(1)
    a = catenoid_parameter(1.0, 0.5)
    rho = np.linalg.norm(V[:, :2], axis=1)
    V[:, :2] *= (a * np.cosh(V[:, 2] / a) / rho)[:, None]
    observer = problem.observers()[0]

    class State:
        n, tau, vertices, faces = 10, 0.1, V, F
        fixed = np.abs(np.abs(V[:, 2]) - 0.5) < 1e-12

    observer(State)
    result = observer.result()
    assert abs(result["neck_error"]) < 1e-12 and abs(result["max_radial_error"]) < 1e-12


def test_time_steps_refuse_what_is_not_a_multiple():
    assert time_steps(0.08, 0.01) == 8
    with pytest.raises(ValueError, match="not a whole multiple of tau = 0.03"):
        time_steps(0.08, 0.03)
    with pytest.raises(ValueError, match="tau must be a positive number"):
        time_steps(0.08, float("nan"))


def test_user_mesh_problem_uses_the_mesh_size():
    problem = Problem.user_mesh("my.obj", steps=7, tau_edge=0.5)
    V, F = get_problem("sphere").mesh(2)
    from mcfbench.geometry.metrics import mean_edge_length

    assert problem.tau(0, (V, F)) == pytest.approx(0.5 * mean_edge_length(V, F) ** 2)
    assert problem.time_steps(0.01) == 7


@pytest.mark.parametrize("scheme", sorted(SCHEMES))
def test_every_scheme_runs_a_marching_cubes_mesh_or_names_why_not(scheme):
    """A scanned-like mesh (slivers, irregular valences): a few steps, no traceback."""
    result, traj = run(scheme, "blobby", 1, t_final=None)
    assert result.status in STATUSES
    assert result.steps_done == result.N or result.message.startswith(
        f"{result.status} at step {traj.failed_step}")
    assert result.min_angle >= 0.0 and result.iterations >= 0


# ------------------------------------------------------------ problems as drop-in modules

TINY = '''"""A unit sphere at level 1-2 with its radius as the metric (a drop-in problem)."""

import numpy as np

from mcfbench.running.problem import Problem


def surface(subdivisions=1):
    from mcfbench.geometry.spheres import icosphere

    return icosphere(subdivisions)


class Radius:
    """Mean distance of the vertices from the origin at the end of the run."""

    def __init__(self, problem):
        self.r = np.nan

    def __call__(self, flow):
        self.r = float(np.linalg.norm(flow.vertices, axis=1).mean())

    def result(self):
        return {"mean_radius": self.r}


METRICS = {"mean_radius": Radius}

PROBLEM = Problem("tiny_sphere", "a sphere from a drop-in module", "tiny_icosphere",
                  lambda level: {"subdivisions": int(level)}, levels=(1, 2), tau_1=0.04,
                  t_final=0.04, metrics=("mean_radius",), exact="R(t) = sqrt(1 - 4t)",
                  main_metric="mean_radius")
'''


def test_a_problem_is_one_file_found_by_the_registry(tmp_path, monkeypatch):
    """One new module, no other file edited: the registry finds the problem, its
    surface, its observer and its main metric; the matrix plans it and a run measures it."""
    from mcfbench.geometry import surfaces
    from mcfbench.running import observers, problems
    from mcfbench.running.run import run
    from mcfbench.studies.matrix import plan as matrix_plan
    from mcfbench.studies.matrix.tables import main_metric

    package = tmp_path / "dropin_problems"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "tiny_sphere.py").write_text(TINY)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setattr(problems, "PROBLEMS", dict(problems.PROBLEMS))
    monkeypatch.setattr(observers, "METRICS", dict(observers.METRICS))
    monkeypatch.setattr(surfaces, "SURFACES", dict(surfaces.SURFACES))

    assert problems.discover_problems([str(package)], "dropin_problems") == ["tiny_sphere"]
    problem = problems.get_problem("tiny_sphere")
    assert list(problems.PROBLEMS)[-1] == "tiny_sphere"
    assert main_metric(problem, ["mean_radius"]) == "mean_radius"
    V, F = problem.mesh(1)
    assert V.shape == (42, 3) and F.shape == (80, 3)
    plan = matrix_plan.plan({"schemes": ["cotan"], "problems": {}})
    assert plan["problems"]["tiny_sphere"] == [1, 2]
    result, _ = run("cotan", problem, 1)
    # one step of tau = 0.04 from the unit sphere: R = sqrt(1 - 4 tau) = 0.916..., up to h^2
    assert result.status == "ok" and result.steps_done == 1
    assert abs(result.metrics["mean_radius"] - np.sqrt(1 - 4 * 0.04)) < 0.03
    with pytest.raises(ValueError, match="'tiny_sphere' is declared twice: by dropin_problems.tiny_sphere and by dropin_problems.tiny_sphere"):
        problems.discover_problems([str(package)], "dropin_problems")


def test_a_problems_kind_says_what_it_tests():
    """``kind`` decides what the matrix's REAL_WORLD_SURFACES and tau_rule decided before:
    the same 12 real-world-like generated or committed meshes' problems."""
    from mcfbench.studies.matrix import is_real_mesh, is_real_world

    kinds = {name: p.kind for name, p in PROBLEMS.items()}
    assert [n for n, k in kinds.items() if k == "reference"] == ["torus", "dumbbell",
                                                                  "dumbbell_through_pinch"]
    assert [n for n, k in kinds.items() if k == "real_world"] == [
        "perturbed_sphere", "remeshed_sphere", "anisotropic_sphere", "flat_patch", "blobby",
        "marching_torus"]
    assert {n for n, k in kinds.items() if k == "real_mesh"} == \
        {n for n in PROBLEMS if n.startswith("real_")}
    assert all(is_real_world(p) == (p.kind in ("real_world", "real_mesh"))
               and is_real_mesh(p) == (p.kind == "real_mesh") for p in PROBLEMS.values())
    assert all(p.kind != "exact" for p in PROBLEMS.values() if p.tau_rule == "mesh")
    assert Problem.user_mesh("my mesh", steps=3).kind == "real_world"


def test_a_problem_records_the_data_files_it_reads():
    for name, problem in PROBLEMS.items():
        if problem.kind != "real_mesh":
            assert problem.data_files == (), name
            continue
        mesh = name.removeprefix("real_")
        assert all(f.is_file() for f in problem.data_files)
        assert [f.name for f in problem.data_files] == [
            mesh_manifest()[mesh]["file"], f"{mesh}.json", f"{mesh}.npz"]


def test_to_extinction_lets_a_run_pass_t_max():
    sphere = get_problem("sphere")
    with pytest.raises(ValueError, match="set the problem's to_extinction"):
        sphere.time_steps(0.01, 0.3)
    with pytest.raises(ValueError, match="past the extinction time"):
        sphere.time_steps(0.01, 0.25)
    assert sphere.time_steps(0.01, 0.24) == 24
    assert sphere.with_settings(to_extinction=True).time_steps(0.01, 0.3) == 30
    # only the problems whose runs go on past a singularity run to the extinction
    assert [p.name for p in PROBLEMS.values() if p.to_extinction] == ["dumbbell_through_pinch"]
    assert all(p.mesh_strategy != "none" for p in PROBLEMS.values() if p.to_extinction)
