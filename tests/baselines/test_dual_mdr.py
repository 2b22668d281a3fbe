"""The dual-MDR scheme (baselines/dual_mdr.py)."""

import functools

import numpy as np
import pytest
import scipy.sparse as sp
from conftest import cylinder, flat_lattice
from hypothesis import given, note
from hypothesis import strategies as st
from scipy.sparse.linalg import spsolve
from test_mdr import (agrees_under_rigid_motion_and_relabelling,
                      reaches_the_catenoid_keeping_its_boundary, unit_normals)

from baselines.dual_mdr import DualMDRFlow
from baselines.laplacian import cotangent_laplacian
from baselines.mdr import MDRFlow
from mcfbench.geometry.committed_meshes import read_committed_mesh
from mcfbench.geometry.spheres import icosahedron, icosphere, perturbed_sphere
from mcfbench.running.integrators import Euler
from mcfbench.running.problems import get_problem
from mcfbench.running.run import level_sweep
from mcfbench.running.solver import Solver

TIGHT = Solver(method="bicgstab", rtol=1e-12, maxiter=5000)
EXACT = Solver(method="direct", rtol=1e-12)


def area(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]),
                                axis=1).sum()


def by_components(nu, f):
    """The (3n, 3n) matrix of the vertex blocks ``f(nu_c, nu_d)``, unknowns by components."""
    return sp.bmat([[sp.diags(f(c, d)) for d in range(3)] for c in range(3)]).tocsr()


def test_system_is_dm5_dm6_against_an_independent_assembly(noisy_sphere):
    """(DM5)-(DM6) from libigl's stiffness, mass and normals: ``[[D A + N, D A], [0, P D
    A P + N]]``, right-hand side ``[N B, -P D A B]``; ``scaling="none"`` its rows times
    ``m_k / dt``."""
    V, F = noisy_sphere
    tau, n = 0.01, len(V)
    nu, m = unit_normals(V, F)
    DA = sp.block_diag([sp.diags(tau / m) @ cotangent_laplacian(V, F)] * 3).tocsr()
    N = by_components(nu, lambda c, d: nu[:, c] * nu[:, d])
    P = by_components(nu, lambda c, d: float(c == d) - nu[:, c] * nu[:, d])
    M = sp.bmat([[DA + N, DA], [None, P @ DA @ P + N]]).tocsr()
    B = V.T.ravel()
    rhs = np.r_[N @ B, -(P @ DA @ B)].reshape(6, n)
    A, b = DualMDRFlow(V, F, tau).system()
    assert abs(A - M).max() < 1e-13 and np.abs(b - rhs).max() < 1e-14
    A, b = DualMDRFlow(V, F, tau, scaling="none").system()
    rows = np.tile(m / tau, 6)
    assert abs(A - sp.diags(rows) @ M).max() < 1e-9
    np.testing.assert_allclose(b.ravel(), rows * rhs.ravel(), rtol=0, atol=1e-10)


def test_step_solves_the_mixed_system_dm1h_dm4h(noisy_sphere):
    """One step equals the solution of the lumped (8n x 8n) system (DM1h)-(DM4h) in
    ``(v, R, kappa, p)``, assembled here from libigl and solved as one saddle point: the
    elimination is exact, ``R`` included, with either scaling."""
    V, F = noisy_sphere
    n, tau = len(V), 0.01
    nu, m = unit_normals(V, F)
    A3 = sp.block_diag([cotangent_laplacian(V, F)] * 3).tocsr()
    C = sp.vstack([sp.diags(m * nu[:, c]) for c in range(3)]).tocsr()     # (s nu, w)_h
    K = sp.bmat([[C.T, None, -sp.diags(m), None],                        # (DM1h)
                 [A3, None, None, C],                                    # (DM2h)
                 [None, C.T, None, None],                                # (DM3h)
                 [tau * A3, A3, C, None]]).tocsc()                       # (DM4h)
    B = V.T.ravel()
    z = spsolve(K, np.r_[np.zeros(5 * n), -(A3 @ B)])
    v, R = z[:3 * n], z[3 * n:6 * n]
    assert np.abs(R).max() > 1e-3                       # the multiplier is no round-off
    for scaling in ("mass", "none"):
        flow = DualMDRFlow(V, F, tau, scaling=scaling)
        Euler().step(flow, EXACT)
        np.testing.assert_allclose(flow.X.ravel(), B + tau * v, rtol=0, atol=1e-11)
        np.testing.assert_allclose(flow.R.T.ravel(), R, rtol=0, atol=1e-11)


def cases():
    """Closed surfaces and an open one (the 12 x 4 cylinder, its boundary fixed), and a
    committed real mesh; ``tau`` 0.1 (five steps) and 10 (two) times the squared mean
    edge (the sphere's 10 h^2 = 0.90 is past its extinction time 0.25)."""
    nut = read_committed_mesh("nut")
    for name, (V, F) in (("sphere", icosphere(2)), ("perturbed_sphere", perturbed_sphere(2)),
                         ("cylinder", cylinder(12, 4)), ("nut", nut)):
        h = np.linalg.norm(V[F[:, 1]] - V[F[:, 0]], axis=1).mean()
        for k, steps in ((0.1, 5), (10.0, 2)):
            yield pytest.param(V, F, k * h * h, steps, id=f"{name}-{k:g}h2")


@pytest.mark.parametrize("V, F, tau, steps", list(cases()))
def test_energy_law_the_area_falls_by_at_least_tau_kappa_squared(V, F, tau, steps):
    """At every step ``|Gamma^{n+1}| + tau sum_k m_k kappa_k^2 <= |Gamma^n|``, ``kappa_k =
    nu_k . (X^{n+1}_k - X^n_k) / tau`` over the free vertices, ``m_k``, ``nu_k`` of
    ``Gamma^n`` from libigl (``baselines/README.md``, dual-mdr, the energy law): the area
    falls, by at least the dissipation, for small and large steps."""
    flow, stepper = DualMDRFlow(V, F, tau), Euler()
    free = ~flow.fixed
    for k in range(steps):
        X0 = np.array(flow.vertices)
        nu, m = unit_normals(X0, F)
        stepper.step(flow, Solver(method="jacobi-direct", rtol=1e-11))
        X1 = np.array(flow.vertices)
        kappa = np.einsum("kc,kc->k", nu, X1 - X0)[free] / tau
        dissipation = tau * (m[free] * kappa ** 2).sum()
        before, after = area(X0, F), area(X1, F)
        assert dissipation > (1e-3 * before if k == 0 else 0.0)
        assert after + dissipation <= before * (1 + 1e-12), (k, before, after, dissipation)


ENERGY_MESHES = [("sphere", 1), ("catenoid", 1), ("hemisphere", 1), ("enneper", 1),
                 ("torus", 1), ("real_nut", 0), ("real_bob", 0), ("real_noisy_sphere", 0)]
"""The exact-answer problems' meshes (sphere, catenoid, hemisphere, Enneper's patch: open
ones with their boundary kept), the torus's and three real meshes (the matrix's levels)."""


@functools.cache
def energy_mesh(name, level):
    return get_problem(name).mesh(level)


@given(mesh=st.sampled_from(ENERGY_MESHES), log_c=st.floats(-3.0, 2.0),
       jitter=st.floats(0.0, 0.3), seed=st.integers(0, 2 ** 32 - 1))
def test_energy_law_holds_for_any_step_on_the_problems_and_real_meshes(mesh, log_c, jitter,
                                                                       seed):
    """The energy law of the previous test for any step ``tau = 10^log_c h^2`` (1e-3 to
    100 squared mean edges) on the problems' and real meshes, their free vertices moved
    at random by up to ``jitter h`` (a mesh the flow did not make): one step, ``|Gamma^1|
    + tau sum_k m_k kappa_k^2 <= |Gamma^0|`` (round-off 1e-12). One: the law is a step's,
    from any mesh; a second step of 100 h^2 after the first starts from a surface the
    first collapsed, where the sparse LU fails (the nut), which is no question of it."""
    V, F = energy_mesh(*mesh)
    flow = DualMDRFlow(V, F, 1.0)
    free = ~flow.fixed
    h = np.linalg.norm(V[F[:, 1]] - V[F[:, 0]], axis=1).mean()
    moved = np.random.default_rng(seed).uniform(-jitter * h, jitter * h, V.shape)
    V = V + moved * free[:, None]
    tau = 10.0 ** log_c * h * h
    note(f"{mesh}, tau = {tau:.3g} (h = {h:.3g})")
    flow = DualMDRFlow(V, F, tau)
    nu, m = unit_normals(V, F)
    Euler().step(flow, EXACT)
    X1 = np.array(flow.vertices)
    kappa = np.einsum("kc,kc->k", nu, X1 - V)[free] / tau
    dissipation = tau * (m[free] * kappa ** 2).sum()
    before, after = area(V, F), area(X1, F)
    assert dissipation > 0.0
    assert after + dissipation <= before * (1 + 1e-12), (before, after, dissipation)


def test_catenoid_area_never_grows_at_its_steady_state():
    """Towards the catenoid (the 12 x 4 cylinder, 40 steps of ``tau`` 0.05, the area's
    change falling to 4e-10 a step) the area never grows beyond round-off."""
    V, F = cylinder(12, 4)
    flow, stepper = DualMDRFlow(V, F, 0.05), Euler()
    areas = [area(V, F)]
    for _ in range(40):
        stepper.step(flow, TIGHT)
        areas.append(area(np.array(flow.vertices), F))
    change = np.diff(areas) / areas[:-1]
    assert np.all(change <= 1e-13) and 0.5 * change[-5] < change[-1] < 0, change


def test_multiplier_is_tangential_and_zero_at_the_boundary(noisy_sphere):
    """``R . nu = 0`` at every vertex to round-off (DM3h), ``R`` itself not small; on the
    open cylinder (radial noise: the regular one has ``R = 0``) ``R = 0`` at the fixed
    vertices and the boundary stays where it was."""
    V, F = cylinder(12, 4)
    free = ~DualMDRFlow(V, F, 0.01).fixed
    V[free] *= 1.0 + 0.1 * np.random.default_rng(2).random((free.sum(), 1)) * [1, 1, 0]
    for V, F in (noisy_sphere, (V, F)):
        flow, stepper = DualMDRFlow(V, F, 0.01), Euler()
        for _ in range(3):
            nu = unit_normals(np.array(flow.vertices), F)[0]
            stepper.step(flow, EXACT)
            R = flow.R
            assert np.abs(R).max() > 1e-4
            assert np.abs(np.einsum("kc,kc->k", R, nu)).max() < 1e-12 * np.abs(R).max()
        np.testing.assert_array_equal(R[flow.fixed], 0.0)
        np.testing.assert_array_equal(flow.vertices[flow.fixed], V[flow.fixed])


def test_r_depends_on_the_base_state_alone_and_differs_from_mdr(noisy_sphere):
    """(DM6): the multiplier of a step is that of any ``dt`` (it solves ``P A (B + R) = 0``,
    ``nu . R = 0``); the positions differ from MDR's by ``dt nu nu^T A R / m`` (DM5)."""
    V, F = noisy_sphere
    Rs = []
    for tau in (0.001, 0.1):
        flow = DualMDRFlow(V, F, tau)
        Euler().step(flow, EXACT)
        Rs.append(np.array(flow.R))
    np.testing.assert_allclose(Rs[0], Rs[1], rtol=0, atol=1e-12)
    dual, mdr = DualMDRFlow(V, F, 0.01), MDRFlow(V, F, 0.01)
    for flow in (dual, mdr):
        Euler().step(flow, TIGHT)
    gap = np.abs(dual.vertices - mdr.vertices).max()
    assert 1e-6 < gap < 1e-3


def test_a_plane_stays_still_even_if_its_mesh_is_irregular():
    """On a flat jittered mesh ``A X`` has no tangential part: ``R = 0`` and ``X = B``."""
    V, F = flat_lattice(6, 5)
    inner = (V[:, 0] % 6 > 0) & (V[:, 1] % 5 > 0)
    V[inner, :2] += 0.2 * np.random.default_rng(1).uniform(-1, 1, (inner.sum(), 2))
    flow = DualMDRFlow(V, F, 0.01)
    for _ in range(3):
        Euler().step(flow, TIGHT)
    np.testing.assert_allclose(flow.vertices, V, rtol=0, atol=1e-13)
    np.testing.assert_allclose(flow.R, 0.0, rtol=0, atol=1e-13)


def test_icosahedron_shrinks_radially_with_no_multiplier():
    """The regular icosahedron: ``R = 0`` by symmetry, one common radius."""
    V, F = icosahedron()
    flow = DualMDRFlow(V, F, 0.01)
    for _ in range(4):
        Euler().step(flow, TIGHT)
        X = flow.vertices
        r = np.linalg.norm(X, axis=1)
        np.testing.assert_allclose(np.cross(X, V), 0.0, atol=1e-13)
        np.testing.assert_allclose(r, r[0], rtol=1e-13)
        np.testing.assert_allclose(flow.R, 0.0, atol=1e-13)
    assert r[0] < np.linalg.norm(V[0])


def test_invariant_under_rigid_motion_and_relabelling(noisy_sphere):
    agrees_under_rigid_motion_and_relabelling(DualMDRFlow, *noisy_sphere)


def test_sphere_is_second_order_in_space():
    """Table 3.1 setting, levels 1-2 (the registry's run: BiCGStab, rtol 1e-9): 1.4464e-2,
    3.3663e-3, EOC 2.10 (level 3: 8.213e-4, EOC 2.04; ``baselines/README.md``)."""
    table = level_sweep("dual-mdr", "sphere", [1, 2])
    assert (table["status"] == "ok").all()
    np.testing.assert_allclose(table["l2_error"], [1.4464e-2, 3.3663e-3], rtol=1e-3)
    assert 2.0 < table["eoc_l2_error"].iloc[1] < 2.2


def test_catenoid_is_second_order_with_its_boundary_kept():
    """Largest radial error 3.507e-3, 8.646e-4 (MDR 3.477e-3, 8.58e-4)."""
    reaches_the_catenoid_keeping_its_boundary("dual-mdr", DualMDRFlow, [3.507e-3, 8.646e-4])


def test_non_finite_multiplier_is_degenerated():
    V, F = icosphere(1)
    flow = DualMDRFlow(V, F, 0.01)
    U = np.array(flow.state)
    U[4, 7] = np.nan
    flow.advance(U)
    assert flow.defects()[0][0] == "degenerated" and "vertex 7" in flow.defects()[0][1]


def test_bad_scaling_is_named():
    with pytest.raises(ValueError, match="unknown scaling 'x'"):
        DualMDRFlow(*icosahedron(), 0.01, scaling="x")
