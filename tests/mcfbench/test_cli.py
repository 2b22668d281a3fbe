"""The command line (mcfbench/cli.py; the console script ``ddfv`` is an alias): its
commands, and the bad-input sweep: every kind of bad input gets an exit status and a
message naming the problem and the offending element or key, never a traceback (bad
meshes, settings and command lines, files that ``export`` cannot read; the pipeline's
config in tests/workflow/test_pipeline.py)."""

import json
import re
import subprocess
import sys

import igl
import numpy as np
import pandas as pd
import pytest
from conftest import bumpy_sphere, cylinder

from mcfbench.cli import main
from mcfbench.geometry.spheres import icosphere
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
        lines = capsys.readouterr().out.split("\n\n")[0].splitlines()   # (then the suffixes)
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


def test_run_names_the_escape_of_a_t_vertex(tmp_path, capsys, split_cube_file):
    """A cube split twice (192 triangles): the T-vertices leave their triangles."""
    mesh = split_cube_file
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


# -- the bad-input sweep

TET_V = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n"
TET_F = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n"


def _obj(V, F):
    return "".join(f"v {float(x)!r} {float(y)!r} {float(z)!r}\n" for x, y, z in V) + \
           "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)


def _run(tmp_path, capsys, text, *options, name="mesh.obj", out="run.npz"):
    mesh = tmp_path / name
    if text is not None:
        mesh.write_text(text)
    args = ["run", str(mesh), "--steps", "2", "--out", str(tmp_path / out)]
    args += list(options) if any(o.startswith("--tau") for o in options) else \
        ["--tau", "0.001", *options]
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def _sphere_obj(level=1):
    return _obj(*icosphere(level))


MESHES = [
    # kind, file text, message (a regular expression)
    ("non-manifold edge", TET_V + "v 1 1 1\n" + TET_F + "f 1 2 5\n",
     r"non-manifold.*edge"),
    ("non-manifold vertex (two cones sharing an apex)",
     "v 0 0 0\n" + "".join(f"v {np.cos(a):.6f} {np.sin(a):.6f} 1\n" for a in np.arange(3) * 2.1)
     + "".join(f"v {np.cos(a):.6f} {np.sin(a):.6f} -1\n" for a in np.arange(3) * 2.1)
     + "f 1 2 3\nf 1 3 4\nf 1 4 2\nf 2 4 3\nf 1 6 5\nf 1 7 6\nf 1 5 7\nf 5 6 7\n",
     r"non-manifold vertex.*\b0\b"),
    ("inconsistent orientation", TET_V + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 3 4\n",
     r"orientation"),
    ("duplicate faces", TET_V + TET_F + "f 1 3 2\n", r"duplicate"),
    ("zero-area triangle", TET_V + "v 0.5 0.5 0\n" + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n"
     .replace("f 1 3 2\n", "f 1 3 5\nf 1 5 2\nf 2 5 3\n"), r"zero-area"),
    ("NaN coordinate", "v nan 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n" + TET_F,
     r"(NaN|nan).*vertex 0"),
    ("empty file", "", r"empty"),
    ("not a mesh", "hello world\n", r"mesh\.obj"),
]


@pytest.mark.parametrize("kind, text, message", MESHES, ids=[m[0] for m in MESHES])
def test_bad_meshes_are_refused_with_a_named_element(tmp_path, capsys, kind, text, message):
    code, out, err = _run(tmp_path, capsys, text)
    assert code == 2, (kind, out, err)
    assert err.startswith("error: ") and "Traceback" not in err
    assert re.search(message, err), (kind, err)
    assert not (tmp_path / "run.npz").exists()


def test_unreferenced_vertices_are_dropped_with_a_note(tmp_path, capsys):
    code, out, err = _run(tmp_path, capsys, _sphere_obj() + "v 5 5 5\nv 6 6 6\n",
                          "--scheme", "cotan")
    assert code == 0, err
    assert "dropped 2 unreferenced vertices" in out
    run = np.load(tmp_path / "run.npz")
    assert run["vertices"].shape == (3, 42, 3) and run["vertex_map"].tolist() == list(range(42))


def test_single_triangle_is_an_open_surface_that_stays_put(tmp_path, capsys):
    code, out, err = _run(tmp_path, capsys, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                          "--scheme", "cotan")
    assert code == 0, err
    assert "1 boundary loop" in out
    run = np.load(tmp_path / "run.npz")
    np.testing.assert_array_equal(run["vertices"][-1], run["vertices"][0])


def test_disconnected_components_flow_each_on_its_own(tmp_path, capsys):
    V, F = icosphere(1)
    both = _obj(np.vstack([V, V + 3.0]), np.vstack([F, F + len(V)]))
    code, out, err = _run(tmp_path, capsys, both, "--scheme", "cotan")
    assert code == 0, err
    assert "2 components" in out
    run = np.load(tmp_path / "run.npz")
    np.testing.assert_allclose(run["vertices"][-1, :42], run["vertices"][-1, 42:] - 3.0, atol=1e-9)


@pytest.mark.parametrize("name, text, message", [
    ("mesh.txt", TET_V + TET_F, r"unsupported mesh format '\.txt'"),
    ("missing.obj", None, r"mesh file not found"),
])
def test_bad_paths_are_named(tmp_path, capsys, name, text, message):
    code, out, err = _run(tmp_path, capsys, text, name=name)
    assert code == 2 and re.search(message, err), err


@pytest.mark.parametrize("options, message", [
    (["--tau", "0"], r"--tau: must be a positive number"),
    (["--tau", "-1"], r"--tau: must be a positive number"),
    (["--tau", "nan"], r"--tau: must be a positive number"),
    (["--steps", "0"], r"--steps: must be a whole number >= 1"),
    (["--rtol", "0"], r"--rtol: must be a positive number"),
    (["--scheme", "fast"], r"--scheme: unknown scheme 'fast'"),
    (["--scheme", "cotan+remesh@bdf2"], r"--scheme: scheme 'cotan\+remesh@bdf2': unknown mesh "
                                        r"strategy 'remesh@bdf2'"),
    (["--solver", "magic"], r"--solver: invalid choice: 'magic'"),
])
def test_bad_settings_are_named(tmp_path, capsys, options, message):
    mesh = tmp_path / "sphere.obj"
    mesh.write_text(_sphere_obj())
    args = ["run", str(mesh), "--tau", "0.001", "--steps", "2", "--out",
            str(tmp_path / "run.npz"), *options]
    with pytest.raises(SystemExit) as exit_:
        main(args)
    assert exit_.value.code == 2
    assert re.search(message, capsys.readouterr().err)


def test_save_every_larger_than_steps_keeps_first_and_last(tmp_path, capsys):
    code, out, err = _run(tmp_path, capsys, _sphere_obj(), "--save-every", "10",
                          "--scheme", "cotan")
    assert code == 0, err
    assert np.load(tmp_path / "run.npz")["steps"].tolist() == [0, 2]


def test_unwritable_output_is_refused_before_the_run(tmp_path, capsys):
    (tmp_path / "blocker").write_text("a file")
    code, out, err = _run(tmp_path, capsys, _sphere_obj(), out="blocker/run.npz")
    assert code == 2 and "blocker is a file, not a directory" in err
    assert "wrote" not in out and "mesh:" not in out       # nothing was computed


def test_output_name_is_kept_or_refused(tmp_path, capsys):
    code, out, err = _run(tmp_path, capsys, _sphere_obj(), out="result.dat")
    assert code == 2 and "name it *.npz" in err
    assert not (tmp_path / "result.dat").exists() and not (tmp_path / "result.dat.npz").exists()


def test_tau_past_the_extinction_of_a_sphere_is_named(capsys):
    code = main(["sphere-table", "--levels", "1", "--scheme", "cotan"])
    assert code == 0
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["sphere-table", "--levels", "0"])
    assert "--levels: must be a whole number >= 1" in capsys.readouterr().err


def test_flow_past_extinction_on_a_users_sphere_ends_with_a_named_status(tmp_path, capsys):
    """tau = 10: the first step shrinks the unit sphere to a round one of 0.0006 left (before
    issue #44: ``degenerated`` at step 2, an error); the flow's end, exit code 0."""
    for scheme in ("cotan", "ddfv"):
        code, out, err = _run(tmp_path, capsys, _sphere_obj(2), "--tau", "10", "--steps",
                              "3", "--scheme", scheme)       # extinction at t = 0.25
        assert code == 0 and "error" not in err
        assert "the flow ended: extinct at step 1 (t = 10): component 0 of 1 (162 vertices, " \
               "e.g. vertex 0) vanished round, to a point" in out
        assert str(np.load(tmp_path / "run.npz")["status"]) == "extinct"


def test_ddfv_option_on_another_scheme_is_named(tmp_path, capsys):
    code, out, err = _run(tmp_path, capsys, _sphere_obj(), "--scheme", "cotan",
                          "--t-init", "exact")
    assert code == 2 and "--t-init applies to the DDFV schemes only, not to cotan" in err


# argv (MESH: a sphere's .obj, OUT: a folder) -> the message, a regular expression
BAD_COMMAND_LINES = [
    ([], r"the following arguments are required: command"),
    (["frobnicate"], r"invalid choice: 'frobnicate'"),
    (["study"], r"the following arguments are required: problem"),
    (["study", "sphre"], r"argument problem: invalid choice: 'sphre'"),
    (["study", "sphere", "--levels", "0"], r"--levels: must be a whole number >= 1, got 0"),
    (["study", "sphere", "--rtol", "abc"], r"--rtol: must be a positive number, got 'abc'"),
    (["sphere-table", "--levels", "x"], r"--levels: must be a whole number, got 'x'"),
    (["sphere-table", "--levels", "1", "--scheme", "cotan", "--t-init", "exact"],
     r"--t-init applies to the DDFV schemes only, not to cotan"),
    (["sphere-table", "--csv", "OUT/blocker/table.csv"], r"blocker is a file, not a directory"),
    (["run", "MESH"], r"the following arguments are required: --steps, --out"),
    (["run", "MESH", "--tau", "0.1", "--tau-edge", "1", "--steps", "1", "--out", "OUT/x.npz"],
     r"argument --tau-edge: not allowed with argument --tau"),
    (["run", "MESH", "--tau", "0.1", "--steps", "1", "--out", "OUT/x.txt"],
     r"name it \*\.npz or \*\.pvd"),
    (["run", "MESH", "--tau", "0.1", "--steps", "1", "--out", "OUT/x.npz", "--movie",
      "OUT/x.mp4"], r"--movie .*x\.mp4: the animation is a GIF"),
    (["run", "OUT/none.obj", "--tau", "0.1", "--steps", "1", "--out", "OUT/x.npz"],
     r"mesh file not found"),
    (["export", "OUT/run.npz"], r"the following arguments are required: out"),
    (["export", "OUT/none.npz", "OUT/x.vtu"], r"name it \*\.pvd or \*\.gif"),
]


def _cli(argv, capsys):
    """``python -m mcfbench ARGV`` in-process: (exit status, standard error). An
    exception other than SystemExit (argparse's) would fail the test: the user
    would have seen its traceback."""
    try:
        code = main(argv)
    except SystemExit as exit_:
        code = exit_.code
    return code, capsys.readouterr().err


@pytest.mark.parametrize("argv, message", BAD_COMMAND_LINES,
                         ids=[" ".join(a) or "(nothing)" for a, _ in BAD_COMMAND_LINES])
def test_bad_command_lines_are_named_in_a_few_lines(tmp_path, capsys, argv, message):
    (tmp_path / "sphere.obj").write_text(_sphere_obj())
    (tmp_path / "blocker").write_text("a file")
    argv = [a.replace("MESH", str(tmp_path / "sphere.obj")).replace("OUT", str(tmp_path))
            for a in argv]
    code, err = _cli(argv, capsys)
    assert code == 2, err
    assert re.search(message, err), err
    assert "Traceback" not in err and "Errno" not in err
    # argparse's: a one-line usage (no option list), the error, where the options are
    assert len(err.splitlines()) <= 3, err
    if err.startswith("usage:"):
        assert "[options]" in err and "--help" in err.splitlines()[-1]


def _write_npz(path, **arrays):
    np.savez(path, **arrays)


BAD_EXPORT_FILES = {  # name -> (how to make it, the message)
    "missing.npz": (None, r"missing\.npz: the file does not exist"),
    "mesh.obj": (lambda p: p.write_text(TET_V + TET_F), r"mesh\.obj: not a run's \.npz"),
    "empty.npz": (lambda p: p.write_bytes(b""), r"empty\.npz: not a run's \.npz"),
    "array.npy": (lambda p: np.save(p, np.zeros(3)), r"array\.npy: not a run's \.npz"),
    "truncated.npz": (lambda p: p.write_bytes(_valid_npz_bytes(p)[:200]),
                      r"truncated\.npz: not a"),
    "objects.npz": (lambda p: _write_npz(p, t=np.array([{"a": 1}], dtype=object)),
                    r"objects\.npz: not a run's \.npz \(it holds Python objects"),
    "other.npz": (lambda p: _write_npz(p, a=np.zeros(3)), r"other\.npz: not a run's frames"),
    "refused.npz": (lambda p: _write_npz(p, faces=np.zeros((0, 3), int), steps=np.zeros(0, int),
                                         t=np.zeros(0)), r"refused\.npz: the run has no frames"),
    "folder.npz": (lambda p: p.mkdir(), r"folder\.npz: a folder, not a run's \.npz"),
}


def _valid_npz_bytes(path):
    V, F = icosphere(0)
    np.savez(path, V=V[None], faces=F, steps=np.zeros(1, int), t=np.zeros(1))
    return path.read_bytes()


@pytest.mark.parametrize("out", ["x.pvd", "x.gif"])
@pytest.mark.parametrize("name", sorted(BAD_EXPORT_FILES))
def test_export_names_a_file_it_cannot_read(tmp_path, capsys, name, out):
    make, message = BAD_EXPORT_FILES[name]
    if make is not None:
        make(tmp_path / name)
    code, err = _cli(["export", str(tmp_path / name), str(tmp_path / out)], capsys)
    assert code == 2 and err.startswith("error: ") and len(err.splitlines()) == 1, err
    assert re.search(message, err), err
    assert "Traceback" not in err and "Errno" not in err and "allow_pickle" not in err
    assert not (tmp_path / out).exists()


def test_a_remeshed_run_writes_frames_with_their_faces_and_schemes_lists_the_suffix(
        tmp_path, capsys):
    """``run --scheme cotan+remesh`` on a mesh of 5.5-degree angles remeshes at step 0: the
    frames file has each frame's faces (version 2); ``schemes`` names the suffix."""
    from mcfbench.geometry.spheres import anisotropic_sphere
    from mcfbench.storage.frames import frame_mesh, load_frames

    V, F = anisotropic_sphere(1)
    mesh = tmp_path / "aniso.obj"
    igl.write_triangle_mesh(str(mesh), V, F)
    out = tmp_path / "run.npz"
    assert main(["run", str(mesh), "--scheme", "cotan+remesh", "--tau-edge", "0.1",
                 "--steps", "4", "--save-every", "2", "--out", str(out)]) == 0
    frames = load_frames(out)
    assert frames["frame_sizes"].shape == (3, 3)
    np.testing.assert_array_equal(frame_mesh(frames, 0)[1], F)
    assert len(frame_mesh(frames, 2)[1]) != len(F)
    capsys.readouterr()
    assert main(["schemes"]) == 0
    assert "+remesh  isotropic remeshing" in capsys.readouterr().out


def test_run_prints_each_continuation_with_its_time_place_components_and_area():
    from mcfbench.cli import _continuation

    cut = {"event": "reextracted", "step": 4, "time": 0.0027285, "where": [0.0, -0.25, -1.5],
           "components_before": 1, "components_after": 2, "area_share": 0.167}
    assert _continuation(cut) == ("step 4 (t = 0.002729): reextracted at (0, -0.25, -1.5), "
                                  "components 1 -> 2, 16.7 % of the initial area removed")
    refused = {"event": "refused", "step": 0, "time": 0.0, "by": "Reextractor",
               "why": "the mesh is open"}
    assert _continuation(refused) == "step 0 (t = 0): refused by Reextractor: the mesh is open"
