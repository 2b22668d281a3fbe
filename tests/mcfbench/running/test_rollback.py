"""A step that folds is rolled back, the state before it remeshed and the step redone
(mcfbench.running.rollback): the run goes on, its cap, its events, no invalid frame."""

import numpy as np
import pytest

from mcfbench.geometry import metrics
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.flow import FlowBreakdown
from mcfbench.running.remeshing import Remesher, mesh_hook
from mcfbench.running.rollback import ROLLBACKS, Rollback
from mcfbench.running.schemes import get_scheme
from mcfbench.storage.frames import surface_points


def _sliver_sphere():
    """A level-2 icosphere with three vertices pushed toward an opposite edge: angles
    of about 0.5 degrees; ``ddfv`` folds one at step 2."""
    V, F = icosphere(2)
    for f in F[[0, 40, 100]]:
        a, b, c = V[f]
        V[f[2]] = (a + b) / 2 + 0.01 * (c - (a + b) / 2)
    return V, F


STEPS = 20


def _run(cap=ROLLBACKS, on_defect="stop"):
    """``ddfv+remesh`` on the sliver sphere with the quality trigger off (``angle=0``):
    only a rollback remeshes."""
    V, F = _sliver_sphere()
    tau = 0.1 * metrics.mean_edge_length(V, F) ** 2
    scheme = get_scheme("ddfv+remesh")
    hook = Remesher(scheme, (V, F), angle=0)
    hook.rollback.cap = cap
    return simulate(scheme.make(V, F, tau), STEPS, remesh=hook, on_defect=on_defect), hook


@pytest.fixture(scope="module")
def rolled():
    return _run()


@pytest.fixture(scope="module")
def capped():
    return _run(cap=0)


def test_without_a_rollback_the_run_ends_inverted_at_step_2(capped):
    traj, hook = capped
    assert traj.status == "inverted" and traj.failed_step == 2, traj.message
    assert traj.steps_done == 2 and hook.calls == 0      # the failed step counted, as without
    assert [e["event"] for e in traj.events] == ["rollback_refused"]
    refused = traj.events[0]
    assert (refused["step"], refused["to_step"], refused["status"]) == (2, 1, "inverted")
    assert "not rolled back: 0 rollbacks in the run already" in refused["why"]
    assert traj.message.startswith("inverted at step 2")     # the fold's, as without


def test_a_run_that_folds_goes_on_after_one_rollback_to_the_end(rolled):
    traj, hook = rolled
    assert traj.status == "ok", traj.message
    assert traj.steps_done == STEPS == len(traj.iterations) and traj.defects == []
    (event,) = traj.events
    assert event["event"] == "rolled_back" and hook.rollback.count == 1 == hook.calls
    assert (event["step"], event["to_step"], event["status"]) == (2, 1, "inverted")
    assert event["time"] == pytest.approx(2 * traj.flow.tau)
    assert "folded" in event["why"] or "invert" in event["why"]
    assert event["min_angle_after"] > 15 > 5 > event["min_angle_before"]     # 2.7 at step 1
    assert abs(event["vertices_after"] / event["vertices_before"] - 1) < 0.25


def test_no_frame_is_of_an_invalid_state(rolled):
    """Every frame, one per level in order, is a sphere's mesh whose triangles all
    face outward (the rolled back state of step 2 never a frame: step 2's frame is the
    redone step's, on the remeshed faces)."""
    traj, _ = rolled
    assert list(traj.steps) == list(range(STEPS + 1))
    for V, F in zip(surface_points(traj.frames)[0], traj.frame_faces, strict=True):
        normals = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        assert (np.einsum("ij,ij->i", normals, V[F].mean(axis=1)) > 0).all()
    assert len(traj.frame_faces[1]) == len(traj.frame_faces[0])     # before: input's
    assert traj.frame_faces[2] is not traj.frame_faces[0]         # after: remeshed


def test_a_run_that_records_its_defects_does_not_roll_back():
    traj, hook = _run(on_defect="record")
    assert traj.status == "inverted" and hook.rollback.count == 0
    assert not any(e["event"].startswith("roll") for e in traj.events)


class _Remesher:
    """A stand-in whose remesh returns a marker flow and the smallest angle it is told
    to leave, and counts its calls."""

    def __init__(self):
        self.asked, self.angle = [], 20.0

    def remeshed(self, flow, V, F, n, why):
        self.asked.append(n)
        return f"flow at {n}", {"event": "remeshed", "step": n, "min_angle_after": self.angle}


class _Flow:
    def __init__(self, n):
        self.n, self.vertices, self.faces = n, np.zeros((3, 3)), np.array([[0, 1, 2]])


def _fold(step, status="inverted"):
    return FlowBreakdown(status, step, 0.1 * step, "a triangle folded")


def test_again_to_one_level_only_while_the_remesh_raises_the_smallest_angle():
    remesher = _Remesher()
    rollback = Rollback(remesher)
    rollback.keep(_Flow(3))
    new, event = rollback(_Flow(4), _fold(4, "t_escaped"))
    assert new == "flow at 3" and event["event"] == "rolled_back"
    assert (event["step"], event["to_step"], event["status"]) == (4, 3, "t_escaped")
    remesher.angle = 25.0                      # the redone step folds again: progress
    rollback.keep(_Flow(3))
    assert rollback(_Flow(4), _fold(4))[0] == "flow at 3"
    rollback.keep(_Flow(3))                    # and again: no progress (25 <= 25)
    new, event = rollback(_Flow(4), _fold(4))
    assert new is None and event["event"] == "rollback_refused"
    assert "folded again after a rollback to it" in event["why"]
    assert "did not raise the smallest angle (25 <= 25 degrees)" in event["why"]
    assert event["min_angle_after"] == 25.0 and rollback.count == 2
    remesher.angle = 10.0                      # another level: allowed at any angle
    rollback.keep(_Flow(7))
    assert rollback(_Flow(8), _fold(8))[0] == "flow at 7"
    assert remesher.asked == [3, 3, 3, 7] and rollback.count == 3


def test_the_cap():
    remesher = _Remesher()
    rollback = Rollback(remesher, cap=2)
    for n in (3, 5):
        rollback.keep(_Flow(n))
        assert rollback(_Flow(n + 1), _fold(n + 1))[0] == f"flow at {n}"
    rollback.keep(_Flow(9))
    new, event = rollback(_Flow(10), _fold(10))
    assert new is None and "2 rollbacks in the run already" in event["why"]
    assert remesher.asked == [3, 5] and rollback.count == 2


def test_a_breakdown_that_is_not_a_fold_is_not_rolled_back():
    rollback = Rollback(_Remesher())
    rollback.keep(_Flow(0))
    assert rollback(_Flow(1), _fold(1, "area_grew")) is None
    assert rollback(_Flow(1), _fold(1, "degenerated")) is None


def test_the_surgery_strategy_rolls_back_through_its_remesher():
    V, F = icosphere(1)
    hook = mesh_hook(get_scheme("cotan+surgery"), (V, F))
    remesher = hook.parts[-1].remesher
    assert hook.rollback is remesher.rollback and remesher.rollback.remesher is remesher


def test_a_runs_record_counts_its_rollbacks(tmp_path):
    """The record's ``rollbacks`` is the run's number of ``rolled_back`` events: the raw
    ``cat_head`` (131 vertices) with ``ddfv+remesh`` reaches step 40 after 2; a record
    written before the key existed reads as 0."""
    import json

    from mcfbench.geometry.committed_meshes import RAW_DIR
    from mcfbench.geometry.mesh_files import read_mesh
    from mcfbench.running.problem import Problem
    from mcfbench.running.run import run
    from mcfbench.storage.records import checksum, read_record, write_record

    V, F, _ = read_mesh(RAW_DIR / "cat_head.obj")
    tau = 0.1 * metrics.mean_edge_length(V, F) ** 2
    result, traj = run("ddfv+remesh", Problem.user_mesh("cat_head", 40, 0.1), 1,
                       mesh=(V, F), tau=tau)
    assert result.status == "ok" and result.steps_done == 40, result.message
    assert result.rollbacks == 2 == [e["event"] for e in traj.events].count("rolled_back")
    path = tmp_path / "run.json"
    record = write_record(path, result, {})
    assert read_record(path)["rollbacks"] == 2
    del record["rollbacks"]
    record["checksum"] = checksum(record)
    path.write_text(json.dumps(record))
    assert read_record(path)["rollbacks"] == 0
