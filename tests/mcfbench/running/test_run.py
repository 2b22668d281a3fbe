"""Studies for any scheme on any problem (mcfbench/running/run.py)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import FailsAt

from mcfbench.geometry.spheres import icosphere
from mcfbench.running.problems import get_problem
from mcfbench.running.run import (
    SHORT_RUN,
    has_boundary,
    level_sweep,
    problem_mesh,
    run,
    space_convergence,
    time_convergence,
)
from mcfbench.running.solver import Solver


@pytest.mark.parametrize("scheme", ["ddfv", "cotan"])
def test_time_convergence_is_first_order(scheme):
    table = time_convergence(scheme, "sphere", 2, [0.01, 0.005, 0.0025], reference_factor=16)
    assert (table.status == "ok").all()
    assert np.all(np.abs(table.eoc[1:] - 1) < 0.15), table.eoc.tolist()
    assert table.l2_error.is_monotonic_decreasing


def test_space_convergence_is_second_order():
    table = space_convergence("ddfv", "sphere", [2, 3], 0.04 / 4**4)
    assert (table.status == "ok").all()
    assert 1.8 < table.eoc_l2_error[1] < 2.3, table.eoc_l2_error.tolist()


def test_level_sweep_reports_eoc_of_every_metric():
    table = level_sweep("cotan", "sphere", [1, 2])
    assert list(table.level) == [1, 2] and np.isnan(table.eoc_l2_error[0])
    assert table.eoc_l2_error[1] == pytest.approx(np.log2(table.l2_error[0] / table.l2_error[1]))


def test_run_records_quality_and_the_t_monitor():
    result, traj = run("ddfv", "sphere", 1)
    assert result.status == "ok" and result.steps_done == result.N == 2
    assert result.nV == 122 and result.nF == 42 and result.nT == 80
    assert len(result.series["t_min_barycentric"]) == 3
    assert 0.2 < result.t_min_barycentric <= 1 / 3
    assert 30 < result.min_angle < 60 and result.max_flipped == 0
    cotan, _ = run("cotan", "sphere", 1)
    assert cotan.nV == cotan.nF == 42 and cotan.nT == 0
    assert np.isnan(cotan.t_min_barycentric)
    # the covolume ratio at every sample: at t = 0 that of the icosphere's lumped mass
    # (cotan) and of the F-covolumes chi of the paper's T-vertices (DDFV, not the same)
    from mcfbench.geometry.metrics import lumped_mass
    from mcfbench.geometry.metrics import covolume_ratio

    V, F = icosphere(1)
    for r in (result, cotan):
        assert len(r.series["covolume_ratio"]) == len(r.series["quality_t"]) == 3
    assert cotan.series["covolume_ratio"][0] == pytest.approx(
        covolume_ratio(lumped_mass(V, F), F), rel=1e-12)
    assert 1.0 < result.series["covolume_ratio"][0] < 2.0


def test_breakdown_keeps_partial_results_and_names_the_time():
    from ddfv.topology import diamond_mesh

    V, F = icosphere(1)
    T0 = V[F].mean(axis=1)
    a, b, t1, t2 = diamond_mesh(F).diamonds[5]
    T0[t1] += 1.3 * (V[a] - T0[t1])          # beyond the corner a: outside at t = 0
    result, traj = run("ddfv", "sphere", 1, T0=T0)
    assert result.status == "t_escaped" and traj.failed_step == 0
    assert result.steps_done == 0 and result.t_failed == 0.0
    assert f"the T-vertex of triangle {t1} left its triangle" in result.message
    assert np.isnan(result.metrics["l2_error"])
    assert traj.steps.tolist() == [0]
    recorded, traj = run("ddfv", "sphere", 1, T0=T0, on_defect="record")
    assert recorded.status == "t_escaped" and recorded.steps_done == recorded.N == 2


def test_running_past_the_extinction_of_the_sphere_is_refused():
    with pytest.raises(ValueError, match="past the extinction time 0.25 of the sphere"):
        run("ddfv", "sphere", 1, tau=0.04, t_final=0.32)


@pytest.mark.parametrize("scheme, level, tau, error", [
    ("cotan", 1, 2.5e-4, 4.6e-3), ("bgn", 3, 5e-4, 8.2e-4), ("ddfv-chord", 2, 2.5e-4, 5.8e-3)])
def test_the_unit_sphere_run_to_its_extinction_ends_within_one_percent(scheme, level, tau,
                                                                      error):
    """Issue #44's target: past t = 0.25 (``to_extinction``) the run ends ``extinct``
    within 1 % of R^2 / 4, its extinction time the last state's time plus the time a
    round sphere of its area has left (:mod:`mcfbench.geometry.collapse`). The levels
    and steps are those where each scheme gets within it: BGN's coarse spheres shrink
    faster (level 2, tau = 5e-4: 0.2445, -2.2 %), the semi-implicit steps lag at the
    end (cotan, level 1, tau = 1e-3: 0.2535, +1.4 %)."""
    problem = get_problem("sphere").with_settings(to_extinction=True)
    result, traj = run(scheme, problem, level, tau=tau, t_final=0.3)
    assert result.status == "extinct", result.message
    assert result.metrics["extinction_time_error"] == pytest.approx(error, abs=1e-4)
    assert abs(result.metrics["extinction_time_error"]) < 0.01
    assert traj.extinction_time == pytest.approx(0.25 * (1 + error), abs=2.5e-5)
    assert traj.t_failed == result.t_failed == result.t_end
    assert 0 < traj.extinction_time - result.t_failed < 2 * tau
    assert np.isnan(result.metrics["l2_error"])       # no error at t_final = 0.3


def test_the_torus_past_its_pinch_ends_extinct_on_its_core_circle():
    """Issue #45, item 2: the torus (2, 0.5) collapses onto its core circle; cotan at
    levels 1-2 ends ``extinct`` (a circle), its extinction time 5.3 % and 2.2 % after the
    axisymmetric reference's pinch at 0.127111 (before: ``degenerated`` at t = 0.148 and
    0.133, the tube shrunk to a line)."""
    errors = []
    for level in (1, 2):
        result, traj = run("cotan", "torus", level)
        assert result.status == "extinct", result.message
        [event] = traj.events
        assert event["kind"] == "circle" and "to a circle" in result.message
        errors.append(result.metrics["pinch_time_error"])
        assert errors[-1] == pytest.approx(traj.extinction_time / 0.127110542534 - 1)
    assert errors == pytest.approx([0.0530, 0.0218], abs=5e-4)


FIRST_AND_SECOND = """
import json, sys
from mcfbench.running.run import level_sweep
out = {}
for scheme in sys.argv[1:]:
    first = level_sweep(scheme, "sphere", [1, 2]).set_index("level")
    second = level_sweep(scheme, "sphere", [2, 1]).set_index("level")
    out[scheme] = [first.cpu_seconds[1], second.cpu_seconds[1], int(first.timing_repeats[1])]
print(json.dumps(out))
"""


def test_the_first_level_of_a_series_carries_no_warm_up():
    """In a fresh process, level 1 timed first (numba's kernels not yet loaded, the
    solver and the scheme never called) and timed second agree within 3 x, for a
    vertex scheme and a DDFV scheme (before the warm-up: 0.16 s against 0.002 s, 80 x).
    The issue's 1.5 x is measured by ``benchmarks/bench_warmup.py`` (0.89-1.12 for every
    scheme); here, on a shared machine, millisecond runs vary by up to 2 x (measured:
    cotan 2.0 ms against 1.1 ms in the full suite under load)."""
    root = Path(__file__).resolve().parents[3]
    env = {**os.environ, "PYTHONPATH": str(root)}
    out = subprocess.run([sys.executable, "-c", FIRST_AND_SECOND, "cotan", "ddfv-chord-carried"],
                         cwd=root, env=env, capture_output=True, text=True, check=True)
    for scheme, (first, second, repeats) in json.loads(out.stdout).items():
        assert 1 / 3 < first / second < 3, (scheme, first, second)
        assert first < SHORT_RUN and repeats > 1, (scheme, first, repeats)


def test_a_short_run_is_timed_as_the_best_of_repeats_a_long_one_once():
    short, _ = run("cotan", "sphere", 1)
    assert short.cpu_seconds < SHORT_RUN and 1 < short.timing_repeats <= 25
    long, _ = run("cotan", "sphere", 1, tau=0.04 / 4**4)             # 512 steps
    assert long.cpu_seconds > SHORT_RUN and long.timing_repeats == 1
    # the run's own result is its first execution's: the same numbers as once
    assert short.steps_done == 2 and short.iterations == 4


def test_a_run_continued_with_the_robust_solver_is_the_robust_run():
    """DDFV with carried T-vertices and BDF2 on the level-2 sphere (162 F-, 320
    T-vertices, 8 steps), BiCGStab failing at step 5, continued with the sparse LU:
    the state, the BDF2 history, the T-vertices and the monitors of step 4 go on as
    they were, so the result is the LU run's from t = 0 to the solvers' tolerance
    (measured: the l2_error agrees to 3e-13 relative)."""
    scheme, lu = "ddfv-chord-carried@bdf2", Solver("direct", rtol=1e-12)
    whole, _ = run(scheme, "sphere", 2, solver=lu)
    failing = FailsAt(rtol=1e-12, at=5, size=whole.nV)
    result, traj, continued = run(scheme, "sphere", 2, solver=failing, robust=lu)
    assert result.status == "solver_failed" and result.steps_done == 4
    assert traj.steps[-1] == 4 and np.isnan(result.metrics["l2_error"])
    assert continued.status == "ok" and continued.solver == "direct"
    assert continued.steps_done == whole.steps_done == 8
    assert continued.iterations == result.iterations > 0          # LU: 0 iterations
    assert continued.metrics["l2_error"] == pytest.approx(whole.metrics["l2_error"], rel=1e-9)
    for key in ("t", "quality_t"):
        assert continued.series[key] == whole.series[key]
    for key in ("t_min_barycentric", "min_angle", "max_aspect", "covolume_ratio"):
        np.testing.assert_allclose(continued.series[key], whole.series[key], rtol=1e-9)
    assert run(scheme, "sphere", 2, solver=lu, robust=lu)[2] is None


def test_a_problem_mesh_is_built_once_and_handed_out_as_copies(monkeypatch):
    torus, built = get_problem("torus"), []
    mesh = type(torus).mesh
    monkeypatch.setattr("mcfbench.running.run._kept_meshes", {})
    monkeypatch.setattr(type(torus), "mesh", lambda self, level: built.append(level) or
                        mesh(self, level))
    V, F = problem_mesh(torus, 1)
    V[:] = 0.0                                       # a flow that moved it in place
    again, faces = problem_mesh(torus, 1)
    np.testing.assert_array_equal(again, torus.mesh(1)[0])
    np.testing.assert_array_equal(faces, F)
    assert again is not V and np.abs(again).max() > 0.5
    assert built == [1, 1]          # once for problem_mesh, once for the comparison


def test_has_boundary():
    assert not has_boundary(icosphere(1)[1])
    assert has_boundary(icosphere(1)[1][1:])


@pytest.mark.parametrize("scheme", ["cotan", "bgn", "ddfv-chord-carried"])
def test_a_two_thread_run_is_the_one_thread_run_to_round_off(scheme):
    """threads=2 (the solver's products and vector passes, DDFV's per-element passes,
    split in blocks; issue 46): the same steps and iterations, positions equal up to the
    inner products' summation order."""
    one, traj_one = run(scheme, "sphere", 3, t_final=0.01)
    two, traj_two = run(scheme, "sphere", 3, t_final=0.01, threads=2)
    assert one.status == two.status == "ok"
    assert traj_one.steps_done == traj_two.steps_done == 4
    np.testing.assert_array_equal(traj_one.iterations, traj_two.iterations)
    X1, X2 = traj_one.frames["vertices"], traj_two.frames["vertices"]
    assert np.abs(X1 - X2).max() <= 1e-13 * np.abs(X1).max()
