import numpy as np
import pytest

from conftest import cylinder
from ddfv import Flow, simulate
from ddfv.surfaces import icosphere
from ddfv.topology import diamond_mesh

TIGHT = dict(rtol=1e-13, t_init="paper")


def _rotation(seed=0):
    q, _ = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def _run(V, F, tau=0.002, steps=6, **options):
    return simulate(V, F, tau, steps, **{**TIGHT, **options})


def test_trajectory_invariant_under_rigid_motion(bumpy):
    V, F = bumpy
    Q, shift = _rotation(), np.array([0.3, -2.0, 1.5])
    ref, moved = _run(V, F), _run(V @ Q.T + shift, F)
    np.testing.assert_allclose(moved.F, ref.F @ Q.T + shift, atol=1e-11)
    np.testing.assert_allclose(moved.T, ref.T @ Q.T + shift, atol=1e-11)


def test_trajectory_invariant_under_scaling_with_tau_times_s2(bumpy):
    V, F = bumpy
    s = 3.0
    ref, scaled = _run(V, F), _run(s * V, F, tau=0.002 * s**2)
    np.testing.assert_allclose(scaled.F, s * ref.F, atol=1e-10 * s)
    np.testing.assert_allclose(scaled.T, s * ref.T, atol=1e-10 * s)


def test_trajectory_invariant_under_relabelling(bumpy):
    V, F = bumpy
    rng = np.random.default_rng(5)
    pv, pt = rng.permutation(len(V)), rng.permutation(len(F))
    new_index = np.empty_like(pv)
    new_index[pv] = np.arange(len(V))           # old vertex pv[k] becomes k
    F2 = np.roll(new_index[F[pt]], 1, axis=1)   # renumbered, reordered, rotated
    ref, relabelled = _run(V, F), _run(V[pv], F2)
    np.testing.assert_allclose(relabelled.F, ref.F[:, pv], atol=1e-11)
    np.testing.assert_allclose(relabelled.T, ref.T[:, pt], atol=1e-11)


@pytest.mark.parametrize("radius", [0.5, 2.0])
def test_sphere_radius_follows_exact_solution(radius):
    V, F = icosphere(3, radius)
    tau = 0.0025 * radius**2
    steps = 40                                        # t = 0.1 R^2: r = 0.775 R
    traj = simulate(V, F, tau, steps, save_every=10)
    exact = np.sqrt(radius**2 - 4 * traj.t)
    r_f = np.linalg.norm(traj.F, axis=2).mean(axis=1)
    r_t = np.linalg.norm(traj.T, axis=2).mean(axis=1)
    # level 3: the error grows to 0.30 % at t = 0.1 R^2 (the radius shrinks 22 %)
    np.testing.assert_allclose(r_f, exact, rtol=5e-3)
    np.testing.assert_allclose(r_t, exact, rtol=5e-3)
    assert traj.status == "ok" and len(traj.t) == 5


def test_frames_follow_save_every(bumpy):
    V, F = bumpy
    traj = simulate(V, F, 0.001, 7, save_every=3)
    np.testing.assert_array_equal(traj.steps, [0, 3, 6, 7])
    np.testing.assert_allclose(traj.t, traj.steps * 0.001)
    assert traj.F.shape == (4, len(V), 3) and traj.T.shape == (4, len(F), 3)
    assert len(traj.iterations) == 7 and len(traj.t_min_barycentric) == 8
    np.testing.assert_array_equal(traj.F[0], V)


def test_solver_failure_is_reported_and_keeps_frames(bumpy):
    V, F = bumpy
    traj = simulate(V, F, 0.01, 5, rtol=1e-15, maxiter=1)
    assert traj.status == "solver_failed" and traj.failed_step == 1
    assert "did not converge at step 1 (t = 0.01)" in traj.message
    assert "relative residual" in traj.message
    assert len(traj.t) == 1 and np.array_equal(traj.F[0], V)


def test_collapse_to_a_point_is_detected():
    V, F = icosphere(2, 0.3)                 # extinction at t = 0.0225
    traj = simulate(V, F, 0.005, 20)
    assert traj.status == "degenerated"
    assert traj.message.startswith(f"mesh degenerated at step {traj.failed_step}")
    assert 5 <= traj.failed_step < 20
    assert traj.steps[-1] == traj.failed_step and len(traj.t) == traj.failed_step + 1


def test_boundary_vertices_stay_fixed():
    V, F = cylinder(16, 6)
    traj = simulate(V, F, 0.002, 10, save_every=5)
    fixed = diamond_mesh(F).boundary_vertices
    assert traj.status == "ok"
    np.testing.assert_array_equal(traj.F[-1][fixed], V[fixed])
    assert np.abs(traj.F[-1][~fixed] - V[~fixed]).max() > 1e-3


def test_elimination_keeps_t_vertices_inside_their_triangles():
    """Section 3.3: the cylinder's T-vertices drift without (3.6), not with it."""
    V, F = cylinder(24, 8)
    plain = simulate(V, F, 0.0025, 800, save_every=0)
    eliminated = simulate(V, F, 0.0025, 800, save_every=0, tangential="eliminate")
    assert plain.t_min_barycentric.min() < 0
    assert eliminated.t_min_barycentric.min() > 0.25


@pytest.mark.parametrize("change, message", [
    (lambda V, F: (np.where(np.arange(len(V))[:, None] == 3, np.nan, V), F), "NaN or inf"),
    (lambda V, F: (np.vstack([V, V[F[0, 0]] + 1e-15 * (V[F[0, 1]] - V[F[0, 0]])]),
                   np.vstack([F[1:], [[F[0, 0], F[0, 1], len(V)], [F[0, 0], len(V), F[0, 2]],
                                      [len(V), F[0, 1], F[0, 2]]]])),
     "zero-area"),
])
def test_bad_vertices_are_named(bumpy, change, message):
    V, F = change(*bumpy)
    with pytest.raises(ValueError, match=message):
        Flow(V, F, 0.01)


@pytest.mark.parametrize("options, message", [
    (dict(tau=0.0), "tau must be a positive number"),
    (dict(tau=float("nan")), "tau must be a positive number"),
    (dict(rtol=2.0), "rtol must lie in"),
    (dict(t_init="middle"), "unknown T-vertex initialisation"),
    (dict(warm_start="zero"), "unknown warm_start"),
    (dict(tangential="some"), "unknown tangential"),
    (dict(T0=np.zeros((3, 3))), "T0 must have shape"),
])
def test_bad_settings_are_named(bumpy, options, message):
    V, F = bumpy
    with pytest.raises(ValueError, match=message):
        Flow(V, F, **{"tau": 0.01, **options})


def test_degenerate_initial_t_vertices_are_refused(bumpy):
    V, F = bumpy
    mesh = diamond_mesh(F)
    a, b, t1, t2 = mesh.diamonds[0]
    T0 = V[F].mean(axis=1)
    T0[t1] = T0[t2] = (V[a] + V[b]) / 2          # v = 0: the diamond collapses
    with pytest.raises(ValueError, match="initial surface is degenerate"):
        Flow(V, F, 0.01, T0=T0)


@pytest.mark.parametrize("bad", [-1, 1.5])
def test_bad_step_counts(bumpy, bad):
    V, F = bumpy
    with pytest.raises(ValueError, match="whole number"):
        simulate(V, F, 0.01, bad)
