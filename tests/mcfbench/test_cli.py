"""The command line (mcfbench/cli.py; the console script ``ddfv`` is an alias)."""

import json
import subprocess
import sys

import igl
import numpy as np
import pandas as pd
import pytest
from conftest import bumpy_sphere, cylinder

from mcfbench.cli import main
from mcfbench.running.schemes import SCHEMES


def test_sphere_table_prints_and_writes_csv(tmp_path, capsys):
    csv = tmp_path / "table.csv"
    assert main(["sphere-table", "--levels", "1", "2", "--csv", str(csv)]) == 0
    out = capsys.readouterr().out
    assert "1.34e-02" in out and "3.26e-03" in out
    table = pd.read_csv(csv)
    for column in "level,nV,nF,nT,tau,N,l2_error,iterations,eoc,cpu_seconds,status".split(","):
        assert column in table.columns
    assert list(table.level) == [1, 2] and list(table.nV) == [122, 482]
    assert abs(table.l2_error[1] / 3.26e-3 - 1) < 0.01
    meta = json.loads((tmp_path / "table.csv.json").read_text())
    assert meta["config"]["levels"] == [1, 2] and "numpy" in meta["packages"]
    assert meta["config"]["scheme"] == "ddfv" and meta["git_commit"] != "unknown"


def test_sphere_table_runs_any_scheme(capsys):
    assert main(["sphere-table", "--levels", "1", "--scheme", "bgn"]) == 0
    out = capsys.readouterr().out
    assert "3.2624e-03" in out                 # BGN's error at level 1 (NOTES.md)
    # a level-1 run takes about 1 ms: its CPU time is the best of repeated runs
    assert "CPU seconds of level(s) 1 (" in out and "as timeit does" in out


def test_study_runs_a_problem_series(tmp_path, capsys):
    csv = tmp_path / "study.csv"
    assert main(["study", "catenoid", "--levels", "1", "--scheme", "ddfv-chord-eliminate",
                 "--csv", str(csv)]) == 0
    table = pd.read_csv(csv)
    assert table.neck_error[0] == pytest.approx(-0.00321, abs=0.00002)   # issue #12
    out = capsys.readouterr().out
    assert "cylinder to catenoid" in out
    # orders of the errors only (the neck radius has no exact value zero); the run's
    # fields (integrator, solver, ...) are not metrics
    assert {c for c in table.columns if c.startswith("eoc_")} == \
        {"eoc_neck_error", "eoc_max_radial_error", "eoc_area_error"}
    header = out.splitlines()[1].split()
    assert "eoc_neck_radius" not in header and "neck_radius" in header
    assert "integrator" not in header and "solver" not in header


def test_registries_are_listed_in_aligned_columns(capsys):
    from mcfbench.running.problems import PROBLEMS

    for command, registry in (("schemes", SCHEMES), ("problems", PROBLEMS)):
        assert main([command]) == 0
        lines = capsys.readouterr().out.splitlines()
        assert [line.split()[0] for line in lines] == list(registry)
        # every description starts in one column, two spaces after the longest name
        start = max(map(len, registry)) + 2
        assert all(line[start - 2:start] == "  " and line[start] != " " for line in lines)


def test_run_help_states_the_frames_kept_by_default(capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["run", "--help"])
    assert exit_.value.code == 0
    assert "(default: 1, every step; 0: first and last only)" in \
        " ".join(capsys.readouterr().out.split())


def test_ddfv_console_script_is_an_alias():
    """``ddfv`` is a console script of the harness's CLI; ``ddfv`` the package has no
    ``__main__`` (it imports nothing of the harness)."""
    from importlib.metadata import entry_points

    scripts = {e.name: e.value for e in entry_points(group="console_scripts")}
    assert scripts["ddfv"] == scripts["mcfbench"] == "mcfbench.cli:main"
    ran = subprocess.run([sys.executable, "-m", "ddfv", "schemes"], capture_output=True, text=True)
    assert ran.returncode == 1 and "No module named ddfv.__main__" in ran.stderr


def test_run_writes_frames(tmp_path):
    V, F = bumpy_sphere(1)
    mesh = tmp_path / "bumpy.obj"
    igl.write_triangle_mesh(str(mesh), V, F)
    out = tmp_path / "run.npz"
    assert main(["run", str(mesh), "--tau", "0.001", "--steps", "5",
                 "--save-every", "2", "--solver", "bicgstab", "--out", str(out)]) == 0
    run = np.load(out)
    assert str(run["scheme"]) == "ddfv"
    assert run["vertices"].shape == (4, len(V), 3) and run["extra_points"].shape == (4, len(F), 3)
    np.testing.assert_array_equal(run["faces"], F)
    np.testing.assert_allclose(run["vertices"][0], V, atol=1e-6)     # OBJ keeps ~7 digits
    np.testing.assert_allclose(run["t"], [0, 0.002, 0.004, 0.005])
    assert len(run["iterations"]) == 5 and str(run["status"]) == "ok"
    assert json.loads(str(run["provenance"]))["config"]["steps"] == 5


def test_run_holds_the_boundary_of_open_meshes(tmp_path):
    V, F = cylinder(12, 4)
    mesh = tmp_path / "cylinder.off"
    igl.write_triangle_mesh(str(mesh), V, F)
    out = tmp_path / "run.npz"
    assert main(["run", str(mesh), "--tau", "0.002", "--steps", "3",
                 "--variant", "eliminate", "--out", str(out)]) == 0
    assert str(np.load(out)["scheme"]) == "ddfv-eliminate"
    run = np.load(out)
    rim = np.abs(np.abs(V[:, 2]) - 0.5) < 1e-12
    np.testing.assert_allclose(run["vertices"][-1][rim], run["vertices"][0][rim])


def test_run_reports_a_breakdown_and_keeps_frames(tmp_path, capsys):
    V, F = bumpy_sphere(1)
    mesh = tmp_path / "bumpy.ply"
    igl.write_triangle_mesh(str(mesh), V, F)
    out = tmp_path / "run.npz"
    assert main(["run", str(mesh), "--tau", "0.01", "--steps", "5", "--rtol", "2",
                 "--out", str(out)]) == 2
    assert "rtol must lie in" in capsys.readouterr().err
    assert main(["run", str(mesh), "--tau", "0.01", "--steps", "5", "--maxiter", "1",
                 "--solver", "bicgstab", "--rtol", "1e-15", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "error: solver_failed at step 1 (t = 0.01): bicgstab did not converge" in err
    assert "iteration limit 1 reached" in err
    run = np.load(out)
    assert str(run["status"]) == "solver_failed" and run["steps"].tolist() == [0]


def test_run_names_the_escape_of_a_t_vertex(tmp_path, capsys):
    """A cube split twice (192 triangles): the T-vertices leave their triangles."""
    from mcfbench.geometry.spheres import subdivide

    V = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    for _ in range(2):
        V, F = subdivide(V, F)
    mesh = tmp_path / "cube.obj"
    igl.write_triangle_mesh(str(mesh), V, F)
    out = tmp_path / "run.npz"
    code = main(["run", str(mesh), "--tau", "0.01", "--steps", "60", "--save-every", "0",
                 "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and "error: t_escaped at step " in err and "left its triangle" in err
    run = np.load(out)
    assert str(run["status"]) == "t_escaped" and run["t_min_barycentric"].min() < 0
    assert json.loads(str(run["defects"]))[0]["status"] == "t_escaped"


def test_missing_mesh_file(tmp_path, capsys):
    assert main(["run", str(tmp_path / "none.obj"), "--tau", "0.1", "--steps", "1",
                 "--out", str(tmp_path / "x.npz")]) == 2
    assert "mesh file not found" in capsys.readouterr().err
