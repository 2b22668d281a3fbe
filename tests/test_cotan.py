"""The cotangent baseline (baselines/cotan.py)."""

import igl
import numpy as np
import pytest

from baselines import cotan
from baselines.cotan import (Assembler, Flow, cotangent_laplacian,
                             lumped_mass, simulate, sphere_run)
from ddfv.errors import SphereL2Error, eoc, sphere_radius
from ddfv.shapes import catenoid_waist, cylinder
from ddfv.solver import SolveInfo
from ddfv.surfaces import icosphere
from ddfv.topology import diamond_mesh


@pytest.fixture(scope="module")
def bumpy_sphere():
    """A level-2 icosphere with radial noise: no symmetry hides index errors."""
    V, F = icosphere(2)
    rng = np.random.default_rng(7)
    return V * (1.0 + 0.1 * rng.random((len(V), 1))), F


def test_laplacian_is_minus_igl_cotmatrix(bumpy_sphere):
    V, F = bumpy_sphere
    L = cotangent_laplacian(V, F)
    np.testing.assert_allclose(L.toarray(), -igl.cotmatrix(V, F).toarray(), rtol=0, atol=0)
    cached = Assembler(diamond_mesh(F, len(V))).laplacian(V)
    np.testing.assert_allclose(cached.toarray(), L.toarray(), rtol=0, atol=1e-14)


def test_laplacian_row_sums_vanish_and_diagonal_is_positive(bumpy_sphere):
    V, F = bumpy_sphere
    for L in (cotangent_laplacian(V, F), Assembler(diamond_mesh(F, len(V))).laplacian(V)):
        assert abs(L - L.T).max() < 1e-14
        assert np.abs(np.asarray(L.sum(axis=1))).max() < 1e-13
        assert L.diagonal().min() > 0
        # positive semi-definite: L X . X is twice the Dirichlet energy >= 0
        assert np.einsum("ij,ij->", V, L @ V) > 0


def test_mass_matches_igl_and_sums_to_area(bumpy_sphere):
    V, F = bumpy_sphere
    area = 0.5 * igl.doublearea(V, F).sum()
    for kind, igl_type in cotan.MASS_TYPES.items():
        m = lumped_mass(V, F, kind)
        np.testing.assert_array_equal(m, igl.massmatrix(V, F, igl_type).diagonal())
        assert m.min() > 0
        assert m.sum() == pytest.approx(area, rel=1e-13)
    flow = Flow(V, F, 0.01)
    np.testing.assert_allclose(flow.mass, lumped_mass(V, F), rtol=1e-14)


def test_system_matrix_is_row_scaled_c1(bumpy_sphere):
    V, F = bumpy_sphere
    tau = 0.003
    for assembly in cotan.ASSEMBLIES:
        A = Flow(V, F, tau, assembly=assembly).system().toarray()
        m = lumped_mass(V, F)
        expected = np.eye(len(V)) + tau * cotangent_laplacian(V, F).toarray() / m[:, None]
        np.testing.assert_allclose(A, expected, rtol=0, atol=1e-13)


def test_sphere_radius_follows_exact_solution():
    # R = 2 on level 3 (642 vertices), tau = 0.01 (tau ~ h^2), t in [0, 0.5],
    # r: 2 -> sqrt(2). Measured max_i,n ||X_i^n| - r(t^n)| / r(t^n):
    # 1.81e-2 (level 2), 5.27e-3 (level 3), 1.34e-3 (level 4): O(h^2 + tau),
    # a factor 3.4-3.9 per level. Tolerance: 1.5x the level-3 value.
    R = 2.0
    V, F = icosphere(3, R)
    traj = simulate(V, F, 0.01, 50, save_every=5)
    assert traj.status == "ok"
    r = sphere_radius(traj.t, R)
    radius = np.linalg.norm(traj.V, axis=2)
    relative = np.abs(radius - r[:, None]).max(axis=1) / r
    assert relative.max() < 8e-3
    assert np.abs(traj.V.mean(axis=1)).max() < 1e-12  # stays centred
    coarse = simulate(*icosphere(2, R), 0.04, 12, save_every=0)
    r_end = sphere_radius(0.5, R)
    err = [np.abs(np.linalg.norm(tr.V[-1], axis=1) - r_end).max() for tr in (coarse, traj)]
    assert err[0] / err[1] > 3.0  # second order in h


def test_sphere_eoc_is_two_on_levels_1_to_3():
    runs = [sphere_run(level) for level in (1, 2, 3)]
    assert all(r.status == "ok" for r in runs)
    orders = eoc([r.l2_error for r in runs])[1:]
    # measured 2.089, 2.037
    assert np.all((orders > 1.95) & (orders < 2.15)), orders


def test_sphere_run_fields():
    run = sphere_run(2)
    assert (run.level, run.nV, run.nF, run.nT, run.N) == (2, 162, 162, 0, 8)
    assert run.variant == "barycentric"
    assert run.tau == pytest.approx(0.01)
    assert np.isnan(run.t_min_barycentric) and np.isnan(run.t_failed)
    assert run.iterations > 0 and run.wall_seconds > 0 and run.status == "ok"
    assert run.l2_error == pytest.approx(3.398e-3, rel=1e-3)


def test_l2_error_definition():
    # one step by hand: sqrt(tau sum_i (|X_i^1| - r(t^1))^2 M_ii^1)
    V, F = icosphere(1)
    error = SphereL2Error()
    flow = Flow(V, F, 0.04)
    flow.step()
    error(flow)
    dist = np.linalg.norm(flow.V, axis=1) - np.sqrt(1 - 4 * 0.04)
    expected = np.sqrt(0.04 * np.sum(dist**2 * lumped_mass(flow.V, F)))
    assert error.value == pytest.approx(expected, rel=1e-14)


def test_assemblies_agree():
    V, F = icosphere(2)
    a = simulate(V, F, 0.01, 8, assembly="cached")
    b = simulate(V, F, 0.01, 8, assembly="igl")
    np.testing.assert_allclose(a.V, b.V, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.iterations, b.iterations)


def test_voronoi_mass_converges_too():
    runs = [sphere_run(level, mass="voronoi") for level in (1, 2, 3)]
    assert runs[0].variant == "voronoi"
    orders = eoc([r.l2_error for r in runs])[1:]
    assert np.all((orders > 1.95) & (orders < 2.15)), orders  # measured 2.106, 2.036


def test_invariant_under_rotation(bumpy_sphere):
    V, F = bumpy_sphere
    Q, _ = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))
    a = simulate(V, F, 0.005, 6)
    b = simulate(V @ Q.T, F, 0.005, 6)
    # the block BiCGStab is rotation-equivariant: Frobenius products are invariant
    np.testing.assert_allclose(b.V @ Q, a.V, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.iterations, b.iterations)


def test_frames_and_observer():
    V, F = icosphere(1)
    seen = []
    traj = simulate(V, F, 0.01, 5, save_every=2, observer=lambda flow: seen.append(flow.n))
    assert seen == [0, 1, 2, 3, 4, 5]
    assert traj.steps.tolist() == [0, 2, 4, 5]
    np.testing.assert_allclose(traj.t, [0, 0.02, 0.04, 0.05])
    assert traj.V.shape == (4, len(V), 3) and len(traj.iterations) == 5
    np.testing.assert_array_equal(traj.V[0], V)
    assert simulate(V, F, 0.01, 3, save_every=0).steps.tolist() == [0, 3]


def test_solver_failure_keeps_frames():
    V, F = icosphere(2)
    traj = simulate(V, F, 0.01, 5, maxiter=1)
    assert traj.status == "solver_failed" and traj.failed_step == 1
    assert "did not converge at step 1" in traj.message
    assert traj.steps.tolist() == [0] and len(traj.iterations) == 0
    # past the extinction time t = 1/4 the flow cannot go on
    late = simulate(V, F, 0.01, 40, save_every=0)
    assert late.status == "solver_failed" and late.failed_step > 25
    assert late.steps.tolist() == [0, late.failed_step - 1]
    run = sphere_run(2, maxiter=1)
    assert run.status == "solver_failed" and np.isnan(run.l2_error)
    assert run.t_failed == pytest.approx(0.01)


def test_degenerate_state_ends_the_run(monkeypatch):
    def broken(A, b, x0, rtol, maxiter):
        return np.full_like(b, np.nan), SolveInfo(1, 0.0, True)

    monkeypatch.setattr(cotan, "bicgstab", broken)
    V, F = icosphere(1)
    traj = simulate(V, F, 0.01, 3)
    assert traj.status == "degenerated" and traj.failed_step == 1
    assert "non-finite" in traj.message
    assert traj.steps.tolist() == [0, 1]  # the degenerate state is kept


@pytest.mark.parametrize("change, message", [
    (dict(tau=0.0), "tau must be a positive"),
    (dict(tau=float("nan")), "tau must be a positive"),
    (dict(rtol=2.0), "rtol must lie in"),
    (dict(maxiter=0), "maxiter must be"),
    (dict(mass="full"), "unknown mass"),
    (dict(assembly="eigen"), "unknown assembly"),
    (dict(steps=-1), "steps must be"),
    (dict(steps=1.5), "steps must be"),
    (dict(save_every=-2), "save_every must be"),
])
def test_bad_parameters(change, message):
    V, F = icosphere(1)
    args = {"vertices": V, "faces": F, "tau": 0.01, "steps": 2, **change}
    with pytest.raises(ValueError, match=message):
        simulate(**args)


def test_bad_meshes():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="NaN or inf"):
        simulate(np.where(np.arange(len(V))[:, None] == 3, np.nan, V), F, 0.01, 1)
    with pytest.raises(ValueError, match="shape"):
        simulate(V[:, :2], F, 0.01, 1)
    with pytest.raises(ValueError, match="face indices"):
        simulate(V[:10], F, 0.01, 1)
    flat = V.copy()
    flat[F[0]] = flat[F[0, 0]] + np.array([[0, 0, 0], [1e-3, 0, 0], [2e-3, 0, 0]])
    with pytest.raises(ValueError, match="degenerate|zero-area"):
        simulate(flat, F, 0.01, 1)
    with pytest.raises(ValueError, match="orientation"):
        simulate(V, np.r_[F[:1, ::-1], F[1:]], 0.01, 1)
    with pytest.raises(ValueError, match="not a multiple"):
        sphere_run(1, tau=0.03)


def test_open_cylinder_keeps_its_boundary_and_approaches_the_catenoid():
    # the cylinder of Figs. 3.5-3.6 (R = 1, h = 0.55, 24 x 8 twisted quads,
    # 216 vertices). Steady state: r(z) = a cosh(z/a), a cosh(h/a) = R,
    # a = 0.8046. Measured waist radius 0.8511 (n = 100), 0.8141 (200),
    # 0.8001 (400); at n = 400 max |r - a cosh(z/a)| = 0.0059 (the
    # discretisation error of 24 segments). Tolerances: 1 % and 0.01.
    V, F = cylinder()
    fixed = diamond_mesh(F, len(V)).boundary_vertices
    assert fixed.sum() == 48
    traj = simulate(V, F, 0.0025, 400, save_every=100)
    assert traj.status == "ok", traj.message
    for X in traj.V:
        np.testing.assert_array_equal(X[fixed], V[fixed])
    r, z = np.hypot(traj.V[..., 0], traj.V[..., 1]), traj.V[..., 2]
    waist = np.where(np.abs(z) < 1e-9, r, np.nan)
    neck = np.nanmean(waist, axis=1)
    assert np.all(np.diff(neck) < 0), neck  # shrinks towards the catenoid
    a = catenoid_waist(1.0, 0.55)
    assert neck[-1] == pytest.approx(a, rel=0.01)
    np.testing.assert_allclose(r[-1], a * np.cosh(z[-1] / a), atol=0.01)


def test_dirichlet_rows_are_identity_in_both_assemblies():
    V, F = cylinder(12, 4)
    flow = {a: Flow(V, F, 0.01, assembly=a) for a in cotan.ASSEMBLIES}
    fixed = flow["cached"].fixed
    A = flow["cached"].system().toarray()
    np.testing.assert_array_equal(A[fixed], np.eye(len(V))[fixed])
    np.testing.assert_allclose(flow["igl"].system().toarray(), A, rtol=0, atol=1e-13)
    free = ~fixed
    expected = np.eye(len(V)) + 0.01 * cotangent_laplacian(V, F).toarray() / \
        lumped_mass(V, F)[:, None]
    np.testing.assert_allclose(A[free], expected[free], rtol=0, atol=1e-13)
    a = simulate(V, F, 0.01, 10, assembly="cached")
    b = simulate(V, F, 0.01, 10, assembly="igl")
    np.testing.assert_allclose(a.V, b.V, rtol=0, atol=1e-12)


def test_sphere_with_a_hole_keeps_the_hole_fixed():
    V, F = icosphere(2)
    traj = simulate(V, F[1:], 0.01, 5)
    assert traj.status == "ok"
    np.testing.assert_array_equal(traj.V[:, F[0]], np.broadcast_to(V[F[0]], (6, 3, 3)))
    free = np.ones(len(V), bool)
    free[F[0]] = False
    # the other vertices shrink (measured radii 0.894-0.927 at t = 0.05; the
    # closed sphere: 0.894)
    assert np.linalg.norm(traj.V[-1, free], axis=1).max() < 0.95
