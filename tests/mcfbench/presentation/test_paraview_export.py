"""ParaView output: ``run --out X.pvd``, ``export RUN.npz X.pvd`` (mcfbench.storage.paraview,
mcfbench.presentation.paraview_export), read back with meshio."""

import json
from pathlib import Path

import igl
import meshio
import numpy as np
import pytest
from conftest import bumpy_sphere

from mcfbench.cli import main
from mcfbench.geometry.metrics import area
from mcfbench.storage.paraview import Piece, read_pvd, write_pvd


def _mesh_file(tmp_path, level=1):
    V, F = bumpy_sphere(level)
    path = tmp_path / "bumpy.obj"
    igl.write_triangle_mesh(str(path), V, F)
    return path


def test_exported_run_reads_back_with_meshio(tmp_path, capsys):
    """cotan, 6 steps, a frame every 2: 4 frames whose points, triangles, times and
    fields are the run's."""
    mesh, npz, pvd = _mesh_file(tmp_path), tmp_path / "run.npz", tmp_path / "out" / "run.pvd"
    assert main(["run", str(mesh), "--scheme", "cotan", "--tau", "0.002", "--steps", "6",
                 "--save-every", "2", "--out", str(npz)]) == 0
    assert main(["export", str(npz), str(pvd)]) == 0
    assert "wrote" in capsys.readouterr().out
    run = np.load(npz)
    collection = read_pvd(pvd)
    np.testing.assert_allclose(collection.times, [0, 0.004, 0.008, 0.012])
    np.testing.assert_array_equal(collection.times, run["t"])
    assert collection.parts == ["surface"] and len(collection.files["surface"]) == 4
    assert sorted(p.name for p in (tmp_path / "out" / "run").iterdir()) == \
        [f"surface_{k:04d}.vtu" for k in range(4)]
    for k in range(4):
        frame = meshio.read(collection.files["surface"][k])
        np.testing.assert_array_equal(frame.points, run["vertices"][k])
        np.testing.assert_array_equal(frame.cells_dict["triangle"], run["faces"])
        moved = run["vertices"][k] - run["vertices"][k - 1] if k else np.zeros_like(run["vertices"][0])
        np.testing.assert_allclose(frame.point_data["displacement"], moved, atol=1e-15)
        # barycentric vertex areas: a third of each triangle, summing to the area
        assert frame.point_data["vertex_area"].sum() == pytest.approx(
            area(run["vertices"][k], run["faces"]), rel=1e-12)
    # the sphere shrinks: every vertex moves inwards over the first two steps
    first = meshio.read(collection.files["surface"][1])
    inward = np.einsum("ij,ij->i", first.point_data["displacement"], run["vertices"][0])
    assert (inward < 0).all()
    meta = collection.provenance
    assert meta["run"]["scheme"] == "cotan" and meta["run"]["status"] == "ok"
    assert meta["run"]["provenance"]["config"]["steps"] == 6
    assert meta["export"]["config"] == {"command": "export", "source": str(npz)}
    assert "meshio" in meta["export"]["packages"]


def test_ddfv_run_writes_t_vertices_and_the_t_monitor(tmp_path, capsys, split_cube_file):
    """The paper's DDFV on a cube split twice: a T-vertex leaves its triangle. The
    collection written by ``run`` holds the T-vertices as their own point set, the
    covolumes of both families (each tiles the surface once) and the T monitor, whose
    value in the last frame is the run's own (negative)."""
    mesh = split_cube_file
    npz, pvd = tmp_path / "run.npz", tmp_path / "run.pvd"
    common = [str(mesh), "--tau", "0.01", "--steps", "60", "--save-every", "0"]
    assert main(["run", *common, "--out", str(npz)]) == 1
    assert main(["run", *common, "--out", str(pvd)]) == 1
    assert "t_escaped" in capsys.readouterr().err
    run = np.load(npz)
    collection = read_pvd(pvd)
    assert collection.parts == ["surface", "t_vertices"]
    np.testing.assert_array_equal(collection.times, run["t"])
    last = len(run["t"]) - 1
    surface, points = collection.read("surface", last), collection.read("t_vertices", last)
    np.testing.assert_array_equal(surface.points, run["vertices"][last])
    np.testing.assert_array_equal(points.points, run["extra_points"][last])
    np.testing.assert_array_equal(points.cells_dict["vertex"].ravel(), np.arange(len(run["faces"])))
    monitor = surface.cell_data["t_monitor"][0]
    np.testing.assert_array_equal(points.point_data["t_monitor"], monitor)
    assert monitor.min() < 0
    assert monitor.min() == pytest.approx(run["t_min_barycentric"][run["steps"][last]],
                                          rel=1e-12)
    first = collection.read("surface", 0)
    assert first.cell_data["t_monitor"][0].min() == pytest.approx(
        run["t_min_barycentric"][0], rel=1e-12)
    assert first.cell_data["t_monitor"][0].min() > 0.29
    chi_f = first.point_data["covolume"]
    chi_t = collection.read("t_vertices", 0).point_data["covolume"]
    assert chi_f.sum() == pytest.approx(chi_t.sum(), rel=1e-12)
    assert (chi_f > 0).all() and (chi_t > 0).all()
    assert collection.provenance["run"]["status"] == "t_escaped"


def test_store_frames_file_exports_with_its_record(tmp_path):
    """A run store's frames file (first and last frames): the collection takes the
    provenance of the record next to it."""
    from mcfbench.running.batch import compute
    from mcfbench.storage.paraview import frame_file
    from mcfbench.storage.run_store import frames_path, record_path
    from mcfbench.studies.matrix import plan as matrix_plan

    plan = matrix_plan.plan({"schemes": ["cotan"], "problems": {"sphere": [1]}})
    spec = matrix_plan.matrix_spec(plan, "cotan", "sphere", 1)
    compute(spec, "c", str(tmp_path / "m"))
    record = Path(record_path(spec, str(tmp_path / "m")))
    frames = Path(frames_path(spec, str(tmp_path / "m")))
    pvd = tmp_path / "sphere.pvd"
    assert main(["export", str(frames), str(pvd)]) == 0
    collection = read_pvd(pvd)
    assert len(collection.times) == 2 and collection.times[0] == 0
    assert collection.times[1] == pytest.approx(json.loads(record.read_text())["t_end"])
    assert collection.provenance["run"]["record"] == record.as_posix()
    assert collection.provenance["run"]["settings"]["problem"] == "sphere"
    assert (pvd.parent / frame_file(pvd, "surface", 1)).is_file()


def test_export_refuses_what_it_cannot_convert(tmp_path, capsys):
    empty = tmp_path / "refused.npz"
    np.savez(empty, faces=np.zeros((0, 3), int), steps=np.zeros(0, int), t=np.zeros(0))
    assert main(["export", str(empty), str(tmp_path / "x.pvd")]) == 2
    assert "the run has no frames" in capsys.readouterr().err
    np.savez(tmp_path / "other.npz", a=np.zeros(3))
    assert main(["export", str(tmp_path / "other.npz"), str(tmp_path / "x.pvd")]) == 2
    assert "not a run's frames file" in capsys.readouterr().err
    assert main(["export", str(empty), str(tmp_path / "x.vtu")]) == 2
    assert "name it *.pvd or *.gif" in capsys.readouterr().err
    assert main(["run", str(_mesh_file(tmp_path)), "--tau", "0.1", "--steps", "1",
                 "--out", str(tmp_path / "x.vtk")]) == 2
    assert "name it *.npz or *.pvd" in capsys.readouterr().err
    assert not list(tmp_path.glob("x*"))


def test_rewrite_removes_stale_frames_and_checks_shapes(tmp_path):
    V = np.eye(3)
    piece = Piece(V, np.array([[0, 1, 2]]), {"a": np.arange(3.0)})
    pvd = tmp_path / "c.pvd"
    write_pvd(pvd, [{"surface": piece}] * 3, [0.0, 1.0, 2.0], {"note": "a -- b"})
    (tmp_path / "c" / "mine.vtu").write_text("a file of the user's")
    write_pvd(pvd, [{"surface": piece}] * 2, [0.0, 1.0], {"note": "a -- b"})
    collection = read_pvd(pvd)
    assert sorted(p.name for p in (tmp_path / "c").iterdir()) == \
        ["mine.vtu", "surface_0000.vtu", "surface_0001.vtu"]
    assert collection.provenance == {"note": "a -- b"}      # "--" survives the XML comment
    with pytest.raises(ValueError, match="frame 0, part 'surface': point field 'a' has shape"):
        write_pvd(pvd, [{"surface": Piece(V, piece.cells, {"a": np.zeros(2)})}], [0.0])
    with pytest.raises(ValueError, match="one finite time per frame"):
        write_pvd(pvd, [{"surface": piece}], [np.nan])
    assert len(read_pvd(pvd).times) == 2                    # the failed writes left it
