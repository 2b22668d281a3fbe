"""The gallery study (mcfbench.studies.gallery): its plan (the config keys ``gallery`` and
``meshes`` checked, each bad key named), one run per mesh file and scheme, its table
from the records and its picture grid."""

import hashlib
import math
from pathlib import Path

import numpy as np
import pytest

from mcfbench.geometry.spheres import icosphere
from mcfbench.running.batch import compute
from mcfbench.running.problems import PROBLEMS
from mcfbench.running.schemes import SCHEMES
from mcfbench.storage.frames import load_frames
from mcfbench.storage.run_store import frames_path, read_runs
from mcfbench.studies.config import ConfigError
from mcfbench.studies.gallery import MESH, job, plan, plots, tables
from mcfbench.studies.matrix import is_real_world
from mcfbench.studies.matrix.plan import robust_method


# ------------------------------------------------------------ the plan


def test_the_plan_s_defaults_and_the_suite_s_own_meshes(capsys):
    """Without a folder: one OBJ per real-world-like problem of the registry at the
    middle level of its series, written under results/gallery/meshes; the defaults
    C 0.1, 40 steps, the robust solver, every scheme."""
    p = plan.plan()
    assert (p["C"], p["steps"], p["solver"], p["rtol"], p["maxiter"]) == \
        (0.1, 40, robust_method(), 1e-9, 1000)
    assert p["schemes"] == list(SCHEMES)
    own = {name: entry for name, entry in p["generated"].items() if entry[0] == "problem"}
    expected = [q for q in PROBLEMS.values() if is_real_world(q)]
    assert sorted(own) == sorted(f"{q.name}.obj" for q in expected)
    for q in expected:
        assert own[f"{q.name}.obj"] == ("problem", q.name, sorted(q.levels)[len(q.levels) // 2])
    assert p["meshes"] == {name: MESH.format(mesh=name) for name in p["generated"]}
    assert all(kind in ("problem", "packaged") for kind, _, _ in p["generated"].values())


@pytest.mark.parametrize("section, meshes, message", [
    ({"schemes": ["cotan", "nonesuch"]}, None,
     r"'gallery\.schemes': unknown scheme\(s\) \['nonesuch'\]"),
    ({"solver": "gauss"}, None, r"'gallery\.solver': unknown solver 'gauss'"),
    ({"C": 0}, None, r"'gallery\.C': must be > 0, got 0\.0"),
    ({"steps": 0}, None, r"'gallery\.steps': must be >= 1, got 0"),
    ({}, "missing", r"'meshes': .*missing is not a folder"),
    ({}, "empty", r"'meshes': no mesh file \(\.obj \.off \.ply \.stl\) in .*empty"),
])
def test_a_bad_key_is_named(tmp_path, section, meshes, message):
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / "notes.txt").write_text("not a mesh")
    with pytest.raises(ConfigError, match=message):
        plan.plan(section, None if meshes is None else str(tmp_path / meshes))


def test_a_folder_s_mesh_files_and_chosen_schemes(tmp_path):
    for name in ("b.OBJ", "a.off", "c.stl", "notes.txt"):
        (tmp_path / name).write_text("")
    p = plan.plan({"schemes": "cotan", "solver": "direct", "C": 0.5, "steps": 7},
                  str(tmp_path))
    assert p["meshes"] == {n: str(tmp_path / n) for n in ("a.off", "b.OBJ", "c.stl")}
    assert p["generated"] == {} and p["schemes"] == ["cotan"]
    assert (p["C"], p["steps"], p["solver"]) == (0.5, 7, "direct")
    assert plan.from_config({"gallery": {"schemes": ["bgn"]}, "meshes": str(tmp_path)},
                            None)["schemes"] == ["bgn"]


# ------------------------------------------------------------ runs and their table


def test_every_scheme_runs_on_every_file_and_the_table_reads_the_records(tmp_path):
    from mcfbench.geometry.surfaces import make_surface

    meshes = tmp_path / "meshes"
    job.write_obj(meshes / "ball.obj", *make_surface("sphere", level=2))
    (meshes / "broken.off").write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    p = plan.plan({"schemes": ["ddfv", "cotan"], "steps": 3}, str(meshes))
    assert list(p["meshes"]) == ["ball.obj", "broken.off"]
    specs = plan.gallery_specs(p)
    assert {spec.mesh_sha256 for spec in specs.values()} == {
        hashlib.sha256(Path(path).read_bytes()).hexdigest() for path in p["meshes"].values()}
    root = str(tmp_path / "runs")
    for spec in specs.values():
        compute(spec, "test", root)
    records = list(read_runs(dict.fromkeys(specs.values(), "test"), root=root).values())
    triangles = [tables.initial_triangles(load_frames(frames_path(spec, root)))
                 for spec in specs.values()]
    table = tables.gallery_table(records, triangles)
    assert list(table.columns) == tables.GALLERY_COLUMNS
    ball = table[table["mesh"] == "ball.obj"]
    assert ball["status"].tolist() == ["ok", "ok"] and ball["steps_done"].tolist() == [3, 3]
    # the level-2 icosphere: 162 vertices, 320 triangles for DDFV and for the vertex
    # scheme alike (its record's nT, DDFV's T-vertex count, is 0); the refused mesh: none
    assert ball["vertices"].tolist() == [162, 162]
    assert ball["triangles"].tolist() == [320, 320]
    assert [r["nT"] for r in records[:2]] == [320, 0]
    h = ball["h"].iloc[0]
    assert ball["tau"].iloc[0] == pytest.approx(0.1 * h * h)
    broken = table[table["mesh"] == "broken.off"]
    assert (broken["status"] == "unsupported").all() and (broken["steps_done"] == 0).all()
    assert broken["triangles"].isna().all()
    assert broken["message"].str.contains("the mesh was refused").all()
    text = tables.gallery_markdown(table, p)
    assert "same footing" in text and "| ball.obj | ddfv | ok | 3/3 |" in text
    assert "C = 0.1, 3 steps, solver jacobi-direct (rtol 1e-09)" in text


def test_the_table_of_given_records_cell_by_cell():
    def record(mesh, scheme, status, done, triangles, t_failed):
        return {"mesh": mesh, "scheme": scheme, "status": status, "steps_done": done, "N": 40,
                "t_failed": t_failed, "min_angle": 21.5, "max_flipped": 0.0,
                "t_min_barycentric": float("nan"), "cpu_seconds": 0.25, "nF": 12,
                "nT": triangles, "h": 0.5, "tau": 0.025, "solver": "jacobi-direct",
                "message": "" if status == "ok" else "inverted at step 7"}

    table = tables.gallery_table([record("ico.obj", "cotan", "ok", 40, 0, float("nan")),
                                  record("bad.off", "bgn", "inverted", 7, 0, 0.175)],
                                 [20, float("nan")])
    assert table["steps"].tolist() == [40, 40] and table["vertices"].tolist() == [12, 12]
    assert table["triangles"].iloc[0] == 20 and math.isnan(table["triangles"].iloc[1])
    text = tables.gallery_markdown(table, {"C": 0.1, "steps": 40, "solver": "jacobi-direct",
                                           "rtol": 1e-9})
    assert "| ico.obj | cotan | ok | 40/40 | – | 21.5 | 0 | – | 0.25 |" in text
    assert "| bad.off | bgn | inverted | 7/40 | 0.175 | 21.5 | 0 | – | 0.25 |" in text


# ------------------------------------------------------------ the picture grid


def test_the_picture_grid_wraps_each_mesh_s_pictures_onto_lines(monkeypatch):
    """Two meshes, the initial surface and 7 schemes' last frames (one refused): 8
    pictures a mesh at most 6 a line, so 2 lines of 4 a mesh; the notes say the time
    reached, the triangles of the initial surface and the refused run's status."""
    from mcfbench.presentation import picture_grid

    figures = []
    monkeypatch.setattr(picture_grid, "save_figure", lambda fig, *paths, **kw: figures.append(fig))
    monkeypatch.setattr(picture_grid, "panel_image",
                        lambda *args, **kw: np.full((4, 4, 4), 255, np.uint8))
    V, F = icosphere(1)
    schemes = list(SCHEMES)[:7]
    frames = {"vertices": np.stack([V, 0.5 * V]), "faces": F, "t": np.array([0.0, 0.1])}
    ok = {"status": "ok", "steps_done": 40, "tau": 0.0025, "t_failed": float("nan")}
    entries = {(mesh, s): (ok, frames) for mesh in ("a.obj", "b.obj") for s in schemes}
    entries["b.obj", schemes[2]] = ({**ok, "status": "unsupported"}, {"t": np.zeros(0)})
    plots.gallery_grid(entries, [None], ["a.obj", "b.obj"], schemes)
    (fig,) = figures
    assert fig.get_size_inches()[0] == pytest.approx(4 * 1.9 + 0.8)
    grid = fig.axes[0].get_subplotspec().get_gridspec()
    assert (grid.nrows, grid.ncols) == (4, 4)
    assert [ax.get_ylabel() for ax in fig.axes if ax.get_ylabel()] == \
        ["a.obj", "a.obj", "b.obj", "b.obj"]
    notes = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert notes.count("80 triangles") == 2 and notes.count("t = 0.1") == 13
    assert notes.count("unsupported") == 1
    titles = [ax.get_title().replace("\n", " ") for ax in fig.axes]
    labels = ["initial"] + [plots.scheme_style(s)[0] for s in schemes]
    assert titles == labels * 2
