"""Animations of a run's frames (mcfbench.presentation.movie, ``run --movie``, ``export X.gif``)."""

import json

import numpy as np
import pytest
from PIL import Image

from mcfbench.cli import main
from mcfbench.geometry.spheres import icosphere
from mcfbench.presentation.movie import frame_status, write_movie

SCALES = (1.0, 0.8, 0.6, 0.4)


def _shrinking_run(status="ok", failed_step=-1):
    """A sphere scaled by :data:`SCALES` at steps 0, 5, 10, 15 (a vertex scheme's frames)."""
    V, F = icosphere(1)
    return {"vertices": np.stack([s * V for s in SCALES]), "faces": F,
            "t": np.array([0.0, 0.05, 0.1, 0.15]), "steps": np.array([0, 5, 10, 15]),
            "status": status, "message": f"{status} at step 10 (t = 0.1): triangle 3"
            if failed_step >= 0 else "", "failed_step": failed_step}


def _frames(path):
    image = Image.open(path)
    frames = []
    for k in range(image.n_frames):
        image.seek(k)
        frames.append(np.asarray(image.convert("RGB"), dtype=int))
    return image, frames


def test_status_on_each_frame():
    steps = np.array([0, 5, 10, 15])
    assert frame_status(steps) == ["ok"] * 4
    assert frame_status(steps, "t_escaped", 10) == ["ok", "ok", "t_escaped", "t_escaped"]
    assert frame_status(steps, "inverted", 12) == ["ok", "ok", "ok", "inverted"]


def test_one_camera_and_scale_for_every_frame(tmp_path):
    """The drawn sphere's width follows its radius (0.4 of the first at the end), about
    the same centre; 4 frames of 400 x 400 pixels, 4 per second, looping."""
    out = write_movie(_shrinking_run(), tmp_path / "run.gif", title="cotan")
    image, frames = _frames(out)
    assert image.n_frames == 4 and image.size == (400, 400)
    assert image.info["duration"] == 250 and image.info["loop"] == 0
    widths, centres = [], []
    for frame in frames:
        body = frame[60:340]                                  # below the title, above the labels
        ink = np.nonzero((body < 235).any(axis=2).any(axis=0))[0]
        widths.append(ink[-1] - ink[0])
        centres.append(0.5 * (ink[-1] + ink[0]))
    np.testing.assert_allclose(np.array(widths) / widths[0], SCALES, atol=0.03)
    np.testing.assert_allclose(centres, centres[0], atol=3)


def _red(frame):
    """Pixels of the defect colour (#c0261c) in the label strip under the surface."""
    strip = frame[350:]
    return int(((strip[..., 0] > 150) & (strip[..., 1] < 90) & (strip[..., 2] < 90)).sum())


def test_status_turns_red_from_the_defect_on(tmp_path):
    out = write_movie(_shrinking_run("inverted", 10), tmp_path / "run.gif")
    _, frames = _frames(out)
    red = [_red(frame) for frame in frames]
    assert red[0] == red[1] == 0 and red[2] > 50 and red[3] > red[2]   # + the message


def test_export_of_a_store_frames_file_shows_the_status_of_its_record(tmp_path, capsys):
    """A run store's frames file has no status of its own: the GIF takes the record's
    beside it (``{key}.npz`` -> ``{key}.json``), as the ``.pvd`` export does; the
    failed step is ``t_failed / tau`` (10 here), red from there on."""
    run = _shrinking_run()
    frames = tmp_path / "runs" / "sphere" / "cotan" / "level1" / "0123456789abcdef.npz"
    record = frames.with_suffix(".json")
    frames.parent.mkdir(parents=True)
    np.savez(frames, **{key: run[key] for key in ("vertices", "faces", "t", "steps")})
    record.write_text(json.dumps({"scheme": "cotan", "status": "inverted", "tau": 0.01,
                                  "message": "inverted at step 10 (t = 0.1): triangle 3",
                                  "t_failed": 0.1}))
    assert main(["export", str(frames), str(tmp_path / "run.gif")]) == 0
    _, gif = _frames(tmp_path / "run.gif")
    red = [_red(frame) for frame in gif]
    assert red[0] == red[1] == 0 and red[2] > 50 and red[3] > red[2]   # + the message


def test_run_writes_a_movie_and_export_converts_a_run(tmp_path, capsys):
    import igl

    V, F = icosphere(1)
    mesh, npz = tmp_path / "s.obj", tmp_path / "run.npz"
    igl.write_triangle_mesh(str(mesh), V, F)
    assert main(["run", str(mesh), "--scheme", "cotan", "--tau", "0.01", "--steps", "4",
                 "--save-every", "2", "--out", str(npz), "--movie", str(tmp_path / "a.gif")]) == 0
    assert main(["export", str(npz), str(tmp_path / "b.gif")]) == 0
    assert "wrote" in capsys.readouterr().out
    for name in ("a.gif", "b.gif"):
        assert Image.open(tmp_path / name).n_frames == 3
    assert main(["run", str(mesh), "--tau", "0.01", "--steps", "1", "--out", str(npz),
                 "--movie", str(tmp_path / "c.mp4")]) == 2
    assert "name it *.gif" in capsys.readouterr().err
    with pytest.raises(ValueError, match="no frames"):
        write_movie({**_shrinking_run(), "t": np.zeros(0)}, tmp_path / "d.gif")
    assert not list(tmp_path.glob("[cd].*"))


def test_gallery_run_keeps_frames_for_its_movie(tmp_path):
    """A gallery run keeps every ``steps // 20``-th step (here all 8) and its movie has
    one frame each; a mesh the reader refuses gives a one-frame notice."""
    import igl

    from mcfbench.running.batch import compute, mesh_spec
    from mcfbench.storage.run_store import frames_path, mesh_sha256, record_path
    from mcfbench.studies.gallery import plots as gallery_plots

    V, F = icosphere(1)
    mesh = tmp_path / "s.obj"
    igl.write_triangle_mesh(str(mesh), V, F)
    solver = {"method": "direct", "rtol": 1e-9, "maxiter": 1000}
    root = str(tmp_path / "runs")

    def gallery_run(path):
        # C = 0.05: 8 steps reach t = 0.136, before the sphere's extinction at 0.25
        spec = mesh_spec("cotan", str(path), mesh_sha256(path), tau_edge=0.05, steps=8,
                         solver=solver, frames=20)
        return compute(spec, "c", root), record_path(spec, root), frames_path(spec, root)

    result, record, frames = gallery_run(mesh)
    assert result["status"] == "ok" and result["mesh"] == "s.obj"
    assert np.load(frames)["steps"].tolist() == list(range(9))
    gallery_plots.run_movie(record, frames, tmp_path / "cotan.gif")
    assert Image.open(tmp_path / "cotan.gif").n_frames == 9

    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 2\n")
    result, record, frames = gallery_run(bad)
    assert result["status"] == "unsupported"
    gallery_plots.run_movie(record, frames, tmp_path / "bad.gif")
    _, shown = _frames(tmp_path / "bad.gif")
    assert len(shown) == 1                                  # the status, in red
    assert ((shown[0][..., 0] > 150) & (shown[0][..., 1] < 90)).sum() > 50


def test_refused_ddfv_run_still_gets_its_one_frame_movie(tmp_path):
    """A DDFV scheme that refuses a surface (status unsupported) keeps the surface
    as its frames, without T-vertices: the gallery's movie job drew none and raised."""
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.presentation.movie import write_movie

    V, F = icosphere(1)
    out = tmp_path / "refused.gif"
    write_movie({"vertices": np.stack([V, V]), "faces": F, "steps": np.array([0, 0]),
                 "t": np.zeros(2), "status": "unsupported",
                 "message": "unsupported at step 0 (t = 0): two components"}, out)
    assert out.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
