"""The one frame-file layout (mcfbench.storage.frames): a run's frames written and read
back unchanged, the points of any scheme's frames read alike (surface_points), and a
file of another layout named."""

import numpy as np
import pytest

from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.schemes import get_scheme
from mcfbench.running.solver import Solver
from mcfbench.storage.frames import load_frames, save_frames, surface_points


def _frames(name, steps=2):
    """Two kept frames of ``name`` on the level-1 icosphere, and its flow."""
    V, F = icosphere(1)
    flow = get_scheme(name).make(V, F, 1e-3)
    traj = simulate(flow, steps, solver=Solver("direct"), save_every=steps)
    return dict(traj.frames, faces=traj.faces, steps=traj.steps, t=traj.t), flow


@pytest.mark.parametrize("name", ["ddfv", "cotan"])
def test_the_points_of_any_scheme_read_alike_and_survive_the_file(name, tmp_path):
    frames, flow = _frames(name)
    # one layout for every scheme: the mesh vertices, and DDFV's T-vertices besides them
    assert set(frames) - {"faces", "steps", "t"} == (
        {"vertices", "extra_points"} if get_scheme(name).extra_points else {"vertices"})
    vertices, extra = surface_points(frames)
    # the surface mesh's vertices of the last state; DDFV's T-vertices as the extra points
    np.testing.assert_array_equal(vertices[-1], flow.vertices)
    assert vertices.shape == (2, 42, 3)
    if name == "ddfv":
        assert extra.shape == (2, 80, 3)
        np.testing.assert_array_equal(np.concatenate([vertices[-1], extra[-1]]), flow.X.T)
    else:
        assert extra is None
    save_frames(tmp_path / "run.npz", frames)
    back = load_frames(tmp_path / "run.npz")
    assert list(back) == list(frames)
    for key, value in frames.items():
        np.testing.assert_array_equal(back[key], value)
    for a, b in zip(surface_points(back), (vertices, extra)):
        assert (a is None and b is None) or np.array_equal(a, b)


def test_a_run_without_frames_has_no_points(tmp_path):
    empty = {"faces": np.zeros((0, 3), int), "steps": np.zeros(0, int), "t": np.zeros(0)}
    save_frames(tmp_path / "refused.npz", empty)
    assert surface_points(load_frames(tmp_path / "refused.npz")) == (None, None)


def test_another_layout_is_named(tmp_path):
    with pytest.raises(ValueError, match=r"x\.npz: not a run's frames file: it has \['t'\]"):
        save_frames(tmp_path / "x.npz", {"t": np.zeros(1)})
    np.savez(tmp_path / "points.npz", faces=np.zeros((1, 3), int), steps=np.zeros(1, int),
             t=np.zeros(1), X=np.zeros((1, 3, 3)))
    with pytest.raises(ValueError, match="expected faces, steps, t and vertices"):
        load_frames(tmp_path / "points.npz")


@pytest.mark.parametrize("name", ["ddfv", "cotan"])
def test_a_file_of_the_layout_before_reads_as_one_of_this_one(name, tmp_path):
    """Frames files written before the one layout (``V``; DDFV's ``F`` and ``T``) read
    as ``vertices`` and ``extra_points``, their arrays unchanged."""
    frames, _ = _frames(name)
    old = {"F" if name == "ddfv" else "V": frames["vertices"],
           **({"T": frames["extra_points"]} if name == "ddfv" else {}),
           "faces": frames["faces"], "steps": frames["steps"], "t": frames["t"]}
    np.savez(tmp_path / "old.npz", **old)
    back = load_frames(tmp_path / "old.npz")
    assert set(back) == set(frames)
    for key, value in frames.items():
        np.testing.assert_array_equal(back[key], value)


def test_the_file_carries_its_format_version_and_a_newer_one_is_refused(tmp_path):
    """save_frames writes format_version (2); load_frames checks it and drops it, reads
    a file of the layout written before the key (version 0) as it is, and refuses a
    newer version or a key that is no version, naming the file."""
    from mcfbench.storage.frames import FORMAT_VERSION

    empty = {"faces": np.zeros((0, 3), int), "steps": np.zeros(0, int), "t": np.zeros(0)}
    save_frames(tmp_path / "now.npz", empty)
    with np.load(tmp_path / "now.npz") as data:
        assert int(data["format_version"]) == FORMAT_VERSION == 2
    assert set(load_frames(tmp_path / "now.npz")) == {"faces", "steps", "t"}
    np.savez(tmp_path / "before.npz", **empty)
    assert set(load_frames(tmp_path / "before.npz")) == {"faces", "steps", "t"}
    np.savez(tmp_path / "future.npz", **empty, format_version=np.array(3))
    with pytest.raises(ValueError, match=r"future\.npz: a frames file of format_version 3, "
                                         r"written by a newer mcfbench; this one reads "
                                         r"versions up to 2"):
        load_frames(tmp_path / "future.npz")
    np.savez(tmp_path / "odd.npz", **empty, format_version=np.array(1.5))
    with pytest.raises(ValueError, match=r"odd\.npz: format_version 1\.5 is not a version"):
        load_frames(tmp_path / "odd.npz")
