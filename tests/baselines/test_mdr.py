"""The minimal deformation rate scheme (baselines/mdr.py)."""

import igl
import numpy as np
import pytest
import scipy.sparse as sp
from conftest import cylinder, flat_lattice
from scipy.sparse.linalg import spsolve

from baselines.laplacian import cotangent_laplacian
from baselines.mdr import MDRFlow
from mcfbench.geometry.spheres import icosahedron, icosphere
from mcfbench.running.integrators import BDF2, Euler
from mcfbench.running.run import level_sweep
from mcfbench.running.solver import Solver

EXACT = Solver(method="direct", rtol=1e-12)


def unit_normals(V, F):
    """Area-weighted unit vertex normals and the barycentric mass, from libigl."""
    N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    num, dbl = np.zeros((len(V), 3)), np.zeros(len(V))
    for k in range(3):
        np.add.at(num, F[:, k], N)
        np.add.at(dbl, F[:, k], igl.doublearea(V, F))
    return num / np.linalg.norm(num, axis=1)[:, None], dbl / 6.0


def step(flow, stepper=None):
    (stepper or Euler()).step(flow, EXACT)
    return np.array(flow.vertices)


def test_elimination_solves_the_saddle_point_system(noisy_sphere):
    """(M5) gives the velocity of the mixed system (M3)-(M4) with its multiplier kappa,
    assembled here independently (libigl) and solved as one (4n x 4n) saddle point."""
    V, F = noisy_sphere
    n, tau = len(V), 0.01
    nu, m = unit_normals(V, F)
    A3 = sp.block_diag([cotangent_laplacian(V, F)] * 3).tocsr()
    C = sp.vstack([sp.diags(m * nu[:, c]) for c in range(3)])          # (kappa nu, w)_h
    Nt = sp.hstack([sp.diags(nu[:, c]) for c in range(3)])             # nu_k . v_k
    B = V.T.ravel()
    # (M3): A v + C kappa = 0; (M4) times m_k: C^T v + tau Nt A v = -Nt A B
    K = sp.bmat([[A3, C], [C.T + tau * Nt @ A3, None]]).tocsc()
    v = spsolve(K, np.r_[np.zeros(3 * n), -Nt @ (A3 @ B)])[:3 * n]
    for scaling in ("mass", "none"):
        X = step(MDRFlow(V, F, tau, scaling=scaling))
        np.testing.assert_allclose(X.T.ravel(), B + tau * v, rtol=0, atol=1e-12)


def test_matrix_is_bgns_with_unit_normals_and_the_rhs_has_the_tangential_term(noisy_sphere):
    """(M5): ``diag(dt/m) A + nu nu^T`` (BGN's (B4) row-scaled, unit normals) and
    ``nu nu^T B + dt P (A B) / m``, against libigl."""
    V, F = noisy_sphere
    tau = 0.01
    A, b = MDRFlow(V, F, tau).system()
    nu, m = unit_normals(V, F)
    L = cotangent_laplacian(V, F)
    NN = sp.bmat([[sp.diags(nu[:, c] * nu[:, d]) for d in range(3)] for c in range(3)])
    expected = sp.block_diag([sp.diags(tau / m) @ L] * 3) + NN
    np.testing.assert_allclose(A.toarray(), expected.toarray(), rtol=0, atol=1e-12)
    LB = L @ V
    tangential = LB - nu * (nu * LB).sum(axis=1)[:, None]
    np.testing.assert_allclose(b, (NN @ V.T.ravel()).reshape(3, -1)
                               + (tau / m[:, None] * tangential).T, rtol=0, atol=1e-12)
    assert np.abs(tangential).max() > 1e-3


def test_a_plane_stays_still_even_if_its_mesh_is_irregular():
    """A flat mesh is a steady state: MDR moves no vertex, not even tangentially (the
    cotangent Laplacian of a flat mesh annihilates its coordinates), with either
    integrator."""
    V, F = flat_lattice(6, 5)
    inner = (V[:, 0] % 6 > 0) & (V[:, 1] % 5 > 0)
    V[inner, :2] += 0.2 * np.random.default_rng(1).uniform(-1, 1, (inner.sum(), 2))
    for stepper in (Euler(), BDF2()):
        flow = MDRFlow(V, F, 0.05)
        for _ in range(3):
            X = step(flow, stepper)
        np.testing.assert_allclose(X, V, rtol=0, atol=1e-13)


def test_normal_velocity_is_minus_h_nu_to_second_order():
    """On icospheres the normal velocity of one short step is -H = -2: the median error
    over the valence-6 vertices falls 4x per level (0.064, 0.020, 0.0047, 0.0012);
    at the 12 valence-5 vertices it stays near 0.29 (the cotangent mean curvature with
    barycentric mass is not pointwise consistent there, whatever the tangential
    motion), and the tangential velocity vanishes there by symmetry."""
    median = []
    for level in (1, 2, 3, 4):
        V, F = icosphere(level)
        tau = 1e-5          # smaller: the tangential part drowns in rounding (dt P A)
        v = (step(MDRFlow(V, F, tau)) - V) / tau
        nu = V / np.linalg.norm(V, axis=1)[:, None]
        normal = np.einsum("kc,kc->k", v, nu)
        valence = np.bincount(F.ravel())
        median.append(np.median(np.abs(normal + 2.0)[valence == 6]))
        five = valence == 5
        assert np.abs(normal[five] + 2.0).max() < 0.3
        assert np.abs(v[five] - normal[five, None] * nu[five]).max() < 1e-5
    orders = np.log2(np.array(median[:-1]) / median[1:])
    assert np.all(orders > 1.6) and np.all(orders[1:] > 1.9), (median, orders)


def test_icosahedron_shrinks_radially():
    """Every vertex of the regular icosahedron is like every other: no tangential
    motion, one common radius."""
    V, F = icosahedron()
    flow = MDRFlow(V, F, 0.01)
    for _ in range(4):
        X = step(flow)
        r = np.linalg.norm(X, axis=1)
        np.testing.assert_allclose(np.cross(X, V), 0.0, atol=1e-13)
        np.testing.assert_allclose(r, r[0], rtol=1e-13)
    assert r[0] < np.linalg.norm(V[0])


def agrees_under_rigid_motion_and_relabelling(flow_class, V, F):
    """Three BDF2 steps of ``flow_class`` on ``(V, F)``, on a rotated and shifted copy and
    on a relabelled copy (vertices and triangles permuted) give the same surface."""
    Q, _ = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))
    shift = np.array([0.3, -1.2, 2.0])
    rng = np.random.default_rng(5)
    perm = rng.permutation(len(V))
    new = np.empty_like(perm)
    new[perm] = np.arange(len(V))
    F2 = new[F][rng.permutation(len(F))]
    flows = [flow_class(V, F, 0.01), flow_class(V @ Q.T + shift, F, 0.01),
             flow_class(V[perm], F2, 0.01)]
    steppers = [BDF2() for _ in flows]
    for _ in range(3):
        XA, XB, XC = (step(flow, s) for flow, s in zip(flows, steppers))
    np.testing.assert_allclose(XB, XA @ Q.T + shift, rtol=0, atol=1e-10)
    np.testing.assert_allclose(XC[new], XA, rtol=0, atol=1e-12)


def test_invariant_under_rigid_motion_and_relabelling(noisy_sphere):
    agrees_under_rigid_motion_and_relabelling(MDRFlow, *noisy_sphere)


def test_sphere_is_second_order_in_space():
    """Table 3.1 setting, levels 1-3: 1.4464e-2, 3.3800e-3, 8.2425e-4 (cotan's errors
    to 1 %: MDR changes the parametrisation, not the normal motion)."""
    table = level_sweep("mdr", "sphere", [1, 2, 3])
    assert (table["status"] == "ok").all()
    np.testing.assert_allclose(table["l2_error"], [1.4464e-2, 3.3800e-3, 8.2425e-4],
                               rtol=1e-3)
    assert np.all(table["eoc_l2_error"].to_numpy()[1:] > 2.0)


def reaches_the_catenoid_keeping_its_boundary(name, flow_class, errors):
    """The registry's catenoid with scheme ``name``, levels 1-2: the largest radial
    errors ``errors`` (0.2 %) and EOC 2; five BDF2 steps of ``flow_class`` on an open
    cylinder leave its boundary circles exactly where they were."""
    table = level_sweep(name, "catenoid", [1, 2])
    assert (table["status"] == "ok").all()
    np.testing.assert_allclose(table["max_radial_error"], errors, rtol=2e-3)
    assert table["eoc_max_radial_error"].iloc[1] > 1.95
    V, F = cylinder(12, 4)
    flow = flow_class(V, F, 0.002)
    stepper = BDF2()
    for _ in range(5):
        X = step(flow, stepper)
    np.testing.assert_array_equal(X[flow.fixed], V[flow.fixed])
    assert np.abs(X - V).max() > 1e-3


def test_catenoid_is_second_order_with_its_boundary_kept():
    """Largest radial error 3.477e-3, 8.58e-4 (cotan 3.437e-3, 8.42e-4)."""
    reaches_the_catenoid_keeping_its_boundary("mdr", MDRFlow, [3.477e-3, 8.58e-4])


def test_bad_scaling_is_named():
    with pytest.raises(ValueError, match="unknown scaling 'x'"):
        MDRFlow(*icosahedron(), 0.01, scaling="x")
