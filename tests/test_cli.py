import json

import igl
import numpy as np
import pandas as pd

from conftest import bumpy_sphere, cylinder
from ddfv.cli import main


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


def test_run_writes_frames(tmp_path):
    V, F = bumpy_sphere(1)
    mesh = tmp_path / "bumpy.obj"
    igl.write_triangle_mesh(str(mesh), V, F)
    out = tmp_path / "run.npz"
    assert main(["run", str(mesh), "--tau", "0.001", "--steps", "5",
                 "--save-every", "2", "--out", str(out)]) == 0
    run = np.load(out)
    assert run["F"].shape == (4, len(V), 3) and run["T"].shape == (4, len(F), 3)
    np.testing.assert_array_equal(run["faces"], F)
    np.testing.assert_allclose(run["F"][0], V, atol=1e-6)     # OBJ keeps ~7 digits
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
    run = np.load(out)
    rim = np.abs(np.abs(V[:, 2]) - 0.5) < 1e-12
    np.testing.assert_allclose(run["F"][-1][rim], run["F"][0][rim])


def test_run_reports_a_breakdown_and_keeps_frames(tmp_path, capsys):
    V, F = bumpy_sphere(1)
    mesh = tmp_path / "bumpy.ply"
    igl.write_triangle_mesh(str(mesh), V, F)
    out = tmp_path / "run.npz"
    assert main(["run", str(mesh), "--tau", "0.01", "--steps", "5", "--rtol", "2",
                 "--out", str(out)]) == 2
    assert "rtol must lie in" in capsys.readouterr().err
    assert main(["run", str(mesh), "--tau", "0.01", "--steps", "5", "--maxiter", "1",
                 "--rtol", "1e-15", "--out", str(out)]) == 1
    assert "did not converge at step 1" in capsys.readouterr().err
    assert str(np.load(out)["status"]) == "solver_failed"


def test_missing_mesh_file(tmp_path, capsys):
    assert main(["run", str(tmp_path / "none.obj"), "--tau", "0.1", "--steps", "1",
                 "--out", str(tmp_path / "x.npz")]) == 2
    assert "mesh file not found" in capsys.readouterr().err
