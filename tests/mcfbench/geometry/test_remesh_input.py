"""The remesher's input and output checked before and after the compiled call
(mcfbench.geometry.remeshing.remesh): a bad mesh is refused with its defect named,
never passed to gpytoolbox's binding (which crashed the process on such input), and a
run whose state the remesher refuses ends ``degenerated`` with that sentence."""

import numpy as np
import pytest

from mcfbench.geometry import metrics
from mcfbench.geometry.remeshing import RemeshRefused, remesh, target_edge
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.remeshing import Remesher
from mcfbench.running.schemes import get_scheme


def _nan(V, F):
    V = V.copy()
    V[7] = np.nan
    return V, F


def _duplicate(V, F):
    return V, np.r_[F, F[3:4, [1, 2, 0]]]


def _zero_area(V, F):
    V = V.copy()
    a, b, c = F[5]
    V[c] = (V[a] + V[b]) / 2
    return V, F


def _unreferenced(V, F):
    return np.r_[V, [[2.0, 0.0, 0.0]]], F


def _bowtie(V, F):
    """Two spheres sharing one vertex: a non-manifold vertex."""
    W = V + [3.0, 0.0, 0.0]
    W[0] = V[0]
    G = F + len(V)
    G[G == len(V)] = 0
    keep = np.r_[np.arange(len(V)), np.arange(1, len(V)) + len(V)]
    renumber = np.full(2 * len(V), -1)
    renumber[keep] = np.arange(len(keep))
    return np.r_[V, W][keep], renumber[np.r_[F, G]]


@pytest.mark.parametrize("defect, kind", [
    (_nan, "non-finite coordinate"), (_duplicate, "duplicate triangle"),
    (_zero_area, "zero-area triangle"), (_unreferenced, "unreferenced vertex"),
    (_bowtie, "non-manifold vertex")])
def test_a_bad_input_is_refused_naming_its_defect(defect, kind, monkeypatch):
    import gpytoolbox

    def never(*args, **kwargs):
        raise AssertionError("the compiled remesher was called on a bad mesh")

    monkeypatch.setattr(gpytoolbox, "remesh_botsch", never)
    V, F = defect(*icosphere(2))
    with pytest.raises(RemeshRefused, match=f"refused its input \\({kind}\\)"):
        remesh(V, F, 0.2)


@pytest.mark.parametrize("h, passes", [(0.0, 3), (np.nan, 3), (0.2, 0), (0.2, 1.5)])
def test_a_bad_length_or_pass_count_is_refused(h, passes):
    with pytest.raises(RemeshRefused, match="edge length > 0 and whole passes >= 1"):
        remesh(*icosphere(2), h, passes)


def test_a_bad_output_is_refused(monkeypatch):
    import gpytoolbox

    V, F = icosphere(2)
    monkeypatch.setattr(gpytoolbox, "remesh_botsch", lambda *a, **k: (V, np.r_[F, F[:1]]))
    with pytest.raises(RemeshRefused, match="output is not a valid surface \\(duplicate"):
        remesh(V, F, 0.2)


def test_a_good_mesh_is_remeshed_to_about_its_vertex_count():
    V, F = icosphere(3)
    U, G = remesh(V, F, target_edge(V, F))
    assert abs(len(U) / len(V) - 1) < 0.25
    assert U.dtype == np.float64 and G.dtype == np.int64
    assert metrics.min_angle(U, G) > 20


def test_a_run_whose_state_the_remesher_refuses_ends_degenerated_naming_it():
    """A state the flow produced with a NaN coordinate (here planted) reaches the hook:
    the run ends ``degenerated`` at that step with the remesher's sentence."""
    V, F = icosphere(2)
    scheme = get_scheme("cotan+remesh")
    tau = 0.1 * metrics.mean_edge_length(V, F) ** 2
    hook = Remesher(scheme, (V, F), every=tau)
    flow = scheme.make(V, F, tau)

    class Planted:
        before_checks, kept = hook.before_checks, hook.kept

        def __call__(self, flow):
            if flow.n == 2:
                return hook(Bad(flow))
            return hook(flow)

    class Bad:
        def __init__(self, flow):
            self.flow = flow

        def __getattr__(self, name):
            value = getattr(self.flow, name)
            if name == "vertices":
                value = value.copy()
                value[4] = np.inf
            return value

    traj = simulate(flow, 5, remesh=Planted())
    assert traj.status == "degenerated" and traj.failed_step == 2, traj.message
    assert "refused its input (non-finite coordinate)" in traj.message
    assert hook.calls == 1           # step 1 (every tau) remeshed, step 2 refused


def test_a_remesh_that_could_not_lift_the_angle_waits_until_the_angle_halves():
    """After a remesh that left 4 degrees (< 10), the trigger waits for 2 degrees; after
    one that left 30, it is back at 10 (mcfbench.geometry.remeshing.RELAPSE)."""
    from mcfbench.geometry.remeshing import RELAPSE, RemeshTrigger

    def mesh(angle):
        """A right-angled triangle whose smallest angle is ``angle`` degrees."""
        return (np.array([[0.0, 0, 0], [1, 0, 0], [1, np.tan(np.radians(angle)), 0]]),
                np.array([[0, 1, 2]]))

    trigger = RemeshTrigger(10.0)
    assert "smallest angle 5 degrees < 10" in trigger(*mesh(5.0), 0.0)
    trigger.done(0.0, 4.0)
    assert trigger.threshold == RELAPSE * 4.0 == 2.0
    assert trigger(*mesh(3.0), 0.1) is None
    assert "< 2" in trigger(*mesh(1.9), 0.2)
    trigger.done(0.2, 30.0)
    assert trigger.threshold == 10.0 and "< 10" in trigger(*mesh(9.0), 0.3)
