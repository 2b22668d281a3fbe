"""Conformalized mean curvature flow (baselines/cmcf.py)."""

import numpy as np
import pytest
from conftest import cylinder, table_3_1_error

from baselines.cmcf import CMCFFlow
from baselines.cotan import CotanFlow
from baselines.laplacian import cotangent_laplacian, lumped_mass
from mcfbench.geometry.exact import eoc, sphere_radius
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.integrators import Euler
from mcfbench.running.solver import Solver

EXACT = Solver(method="direct", rtol=1e-12)


def test_stiffness_is_the_initial_one_and_mass_the_current(noisy_sphere):
    V, F = noisy_sphere
    L0 = cotangent_laplacian(V, F).toarray()
    for assembly in ("cached", "igl"):
        flow = CMCFFlow(V, F, 0.01, assembly=assembly)
        simulate(flow, 3, solver=Solver())
        X = flow.vertices
        np.testing.assert_allclose(flow.laplacian().toarray(), L0, rtol=0, atol=2e-15)
        assert abs(cotangent_laplacian(X, F).toarray() - L0).max() > 1e-2   # it moved
        A, b = flow.system()
        expected = np.eye(len(V)) + 0.01 * L0 / lumped_mass(X, F)[:, None]     # (K2)
        np.testing.assert_allclose(A.toarray(), expected, rtol=0, atol=1e-13)
        np.testing.assert_array_equal(b, flow.X)
        np.testing.assert_allclose(flow.l2_weights, lumped_mass(X, F), rtol=1e-13)


def test_one_step_is_invariant_under_rigid_motions(noisy_sphere):
    V, F = noisy_sphere
    Q, _ = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))
    shift = np.array([0.3, -1.2, 2.0])
    a, b = CMCFFlow(V, F, 0.01), CMCFFlow(V @ Q.T + shift, F, 0.01)
    for _ in range(2):
        Euler().step(a, EXACT)
        Euler().step(b, EXACT)
    np.testing.assert_allclose(b.vertices, a.vertices @ Q.T + shift, rtol=0, atol=1e-10)


def test_equals_the_cotangent_scheme_while_the_mesh_is_a_scaled_copy():
    # cotangent weights are scale invariant, so L(s X^0) = L^0: on the
    # icosahedron (all vertices alike, the mesh stays a scaled copy) (K1)
    # and the cotangent scheme (C1) are the same scheme
    V, F = icosphere(0)
    a = simulate(CMCFFlow(V, F, 0.01), 20, solver=EXACT).frames["vertices"]
    b = simulate(CotanFlow(V, F, 0.01), 20, solver=EXACT).frames["vertices"]
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-13)
    radius = np.linalg.norm(a, axis=2)
    assert np.ptp(radius, axis=1).max() < 1e-13
    assert radius[-1, 0] < 0.7


def test_sphere_stays_a_sphere_and_shrinks_like_mcf():
    # for the sphere the conformalized flow IS mean curvature flow: with
    # X = s X^0, M(X) = s^2 M^0 and L^0 X = s L^0 X^0 ~ s (2 / R^2) M^0 X^0,
    # so s^2 ds/dt = -(2 / R^2) s, r^2 = R^2 - 4 t (not a different rate)
    R, tau = 2.0, 0.01
    V, F = icosphere(3, R)
    traj = simulate(CMCFFlow(V, F, tau), 50, solver=Solver(), save_every=5)
    assert traj.status == "ok"
    radius = np.linalg.norm(traj.frames["vertices"], axis=2)
    r = sphere_radius(traj.t, R)
    # measured: radial spread <= 2.0e-3 r, |mean radius - r| <= 5.1e-3 r
    # (the cotangent scheme: 2.0e-3 and 5.1e-3)
    assert (np.ptp(radius, axis=1) / r).max() < 3e-3
    assert (np.abs(radius.mean(axis=1) - r) / r).max() < 7e-3
    assert np.all(np.diff(radius.mean(axis=1)) < 0)


def test_sphere_errors_and_eoc_levels_1_to_3():
    # Table 3.1 setting (tau = 0.04 / 4**(level - 1), t = 0.08, error (3.2));
    # within 0.2 % of the cotangent scheme's 1.4464e-2, 3.3985e-3, 8.2796e-4
    errors = [table_3_1_error(CMCFFlow, level)[0] for level in (1, 2, 3)]
    np.testing.assert_allclose(errors, [1.4453472e-2, 3.3945892e-3, 8.2761198e-4], rtol=1e-6)
    orders = eoc(errors)[1:]
    assert np.all((orders > 2.0) & (orders < 2.15)), orders   # 2.09, 2.04


def test_open_cylinder_tends_to_the_harmonic_map_not_the_catenoid():
    # fixed circles r = 1 at z = +-0.5: the steady state solves L^0 X = 0,
    # the harmonic map of the flat cylinder, r(z) = cosh(z) / cosh(0.5)
    # (neck 0.8868), not the catenoid (neck 0.8483). 24 x 8 quads, tau =
    # 0.005: measured neck 0.8943 (t = 0.25), 0.88695 (t = 1).
    V, F = cylinder(24, 8)
    flow = CMCFFlow(V, F, 0.005)
    traj = simulate(flow, 200, solver=Solver(), save_every=50)
    assert traj.status == "ok"
    X = traj.frames["vertices"]
    np.testing.assert_array_equal(X[-1, flow.fixed], V[flow.fixed])
    r, z = np.hypot(X[-1, :, 0], X[-1, :, 1]), X[-1, :, 2]
    np.testing.assert_allclose(r, np.cosh(z) / np.cosh(0.5), atol=5e-4)   # measured 1.3e-4
    # the discrete steady state: L^0_II X_I = -L^0_IB X_B (measured residual 4.9e-7)
    L0 = flow.laplacian()
    interior = ~flow.fixed
    assert np.abs((L0 @ X[-1])[interior]).max() < 1e-5


def test_bad_parameters():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="tau must be a positive"):
        CMCFFlow(V, F, -1.0)
    with pytest.raises(ValueError, match="unknown mass"):
        CMCFFlow(V, F, 0.01, mass="lumped")


def test_registry_entry():
    from mcfbench.running.schemes import get_scheme

    V, F = icosphere(1)
    assert isinstance(get_scheme("cmcf").make(V, F, 0.01), CMCFFlow)
