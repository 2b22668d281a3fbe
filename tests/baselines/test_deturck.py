"""The DeTurck scheme (baselines/deturck.py)."""

import igl
import numpy as np
import pytest
import scipy.sparse as sp
from conftest import flat_lattice
from test_mdr import (agrees_under_rigid_motion_and_relabelling,
                      reaches_the_catenoid_keeping_its_boundary, step)

from baselines.cotan import CotanFlow
from baselines.laplacian import cotangent_laplacian
from baselines.deturck import DeTurckFlow, reference_gradients
from baselines.tangential_kernels import vertex_gradients
from mcfbench.geometry.spheres import icosahedron, icosphere
from mcfbench.running.integrators import BDF2, Euler
from mcfbench.running.run import level_sweep
from mcfbench.running.solver import Solver

EXACT = Solver(method="direct", rtol=1e-12)


def unit_normals(V, F):
    N = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    return N / np.linalg.norm(N, axis=1)[:, None]


def test_system_is_d4_against_an_independent_assembly(noisy_sphere):
    """(D4) at the second state, built from libigl's stiffness, mass, normals and
    per-face gradients: ``Omega + dt diag(1/m) A + dt D``, right-hand side ``Omega B``."""
    Y, F = noisy_sphere
    tau, alpha = 0.01, 0.3
    flow = DeTurckFlow(Y, F, tau, alpha=alpha)
    X = step(flow)                                       # the reference stays Y
    for scaling in ("mass", "none"):
        A, b = flow.system(scaling=scaling)
        L = cotangent_laplacian(X, F)
        m = igl.massmatrix(X, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
        nu, n0 = unit_normals(X, F), unit_normals(Y, F)
        tension = -(L @ Y) / m[:, None]
        tension -= n0 * (n0 * tension).sum(axis=1)[:, None]
        G = igl.grad(Y, F)                                   # (3 m, n): x, y, z blocks
        area = igl.doublearea(Y, F)
        S = sp.csr_matrix((np.tile(area, 3), (F.T.ravel(), np.tile(np.arange(len(F)), 3))))
        mean = sp.diags(1.0 / (S @ np.ones(len(F)))) @ S          # area-weighted over faces
        D = sum(sp.diags(tension[:, c]) @ mean @ G[c * len(F):(c + 1) * len(F)]
                for c in range(3))
        Omega = sp.bmat([[sp.diags(alpha * (c == d) + (1 - alpha) * nu[:, c] * nu[:, d])
                          for d in range(3)] for c in range(3)])
        expected = Omega + tau * sp.block_diag([sp.diags(1 / m) @ L + D] * 3)
        rhs = Omega @ X.T.ravel()
        if scaling == "none":
            rows = sp.diags(np.tile(m / tau, 3))
            expected, rhs = rows @ expected, rows @ rhs
        np.testing.assert_allclose(A.toarray(), expected.toarray(), rtol=0,
                                   atol=1e-11 * abs(expected).max())
        np.testing.assert_allclose(b.ravel(), rhs, rtol=0, atol=1e-11 * np.abs(rhs).max())
    assert np.abs(tension).max() > 1e-3 and abs(A - A.T).max() > 1e-6


def test_reference_gradients_are_the_lumped_vertex_gradients(noisy_sphere):
    V, F = noisy_sphere
    flow = DeTurckFlow(V, F, 0.01)
    p = flow.assembler.pattern
    psi = np.random.default_rng(2).standard_normal(len(V))
    G = reference_gradients(V, F, p)
    grad = np.stack([flow.assembler.csr(G[:, c]) @ psi for c in range(3)], axis=1)
    expected = np.empty((len(V), 3))
    vertex_gradients(V, F, psi, expected)               # projected on the vertex normal
    n0 = unit_normals(V, F)
    np.testing.assert_allclose(grad - n0 * (n0 * grad).sum(axis=1)[:, None], expected,
                               rtol=0, atol=1e-12)
    # exact for the coordinate functions of a flat mesh
    V, F = flat_lattice(4, 3)
    G = reference_gradients(V, F, DeTurckFlow(V, F, 0.01).assembler.pattern)
    P = DeTurckFlow(V, F, 0.01).assembler
    np.testing.assert_allclose(np.stack([P.csr(G[:, c]) @ V[:, 0] for c in range(3)], 1),
                               np.tile([1.0, 0.0, 0.0], (len(V), 1)), atol=1e-14)


def test_alpha_one_is_the_cotangent_system_plus_the_advection(noisy_sphere):
    V, F = noisy_sphere
    flow = DeTurckFlow(V, F, 0.01, alpha=1.0)
    X = step(flow)
    A, b = flow.system()
    n = len(V)
    blocks = [A[c * n:(c + 1) * n, d * n:(d + 1) * n] for c in range(3) for d in range(3)]
    assert all(abs(B).max() == 0 for k, B in enumerate(blocks) if k % 4)   # no coupling
    cotan = CotanFlow(V, F, 0.01)
    cotan.advance(X.T.copy())
    C = cotan.system()[0]
    advection = blocks[0] - C
    assert abs(advection - advection.multiply(sp.csr_matrix(C != 0))).max() < 1e-15
    assert abs(advection).max() > 1e-6 and np.allclose(b, X.T, rtol=0, atol=1e-15)


def test_a_plane_stays_still_even_if_its_mesh_is_irregular():
    """The coordinates of a flat mesh are discrete-harmonic on it: no tension, no
    tangential motion, ``X = B`` (either integrator)."""
    V, F = flat_lattice(6, 5)
    inner = (V[:, 0] % 6 > 0) & (V[:, 1] % 5 > 0)
    V[inner, :2] += 0.2 * np.random.default_rng(1).uniform(-1, 1, (inner.sum(), 2))
    for stepper in (Euler(), BDF2()):
        flow = DeTurckFlow(V, F, 0.05)
        assert np.abs(flow.tension()[~flow.fixed]).max() < 1e-13
        for _ in range(3):
            X = step(flow, stepper)
        np.testing.assert_allclose(X, V, rtol=0, atol=1e-13)


def test_normal_velocity_is_minus_h_nu_and_symmetric_vertices_move_radially():
    """One short step on icospheres: median error of the normal velocity (-2) over the
    valence-6 vertices 0.064, 0.020, 0.0047, 0.0012 (levels 1-4, as MDR's and
    cotan's: the normal motion is mean curvature flow whatever alpha); no
    tangential velocity at the 12 valence-5 vertices (symmetry) nor anywhere on the
    level-1 sphere (its tension vanishes: every vertex is fixed by a rotation)."""
    median = []
    for level in (1, 2, 3, 4):
        V, F = icosphere(level)
        flow = DeTurckFlow(V, F, 1e-5)
        v = (step(flow) - V) / 1e-5
        nu = V / np.linalg.norm(V, axis=1)[:, None]
        normal = np.einsum("kc,kc->k", v, nu)
        tangential = v - normal[:, None] * nu
        valence = np.bincount(F.ravel())
        median.append(np.median(np.abs(normal + 2.0)[valence == 6]))
        assert np.abs(tangential[valence == 5]).max() < 1e-5
        assert (np.abs(tangential).max() < 1e-5) == (level == 1)
    orders = np.log2(np.array(median[:-1]) / median[1:])
    assert np.all(orders > 1.6) and np.all(orders[1:] > 1.9), (median, orders)


def test_icosahedron_shrinks_radially():
    V, F = icosahedron()
    flow = DeTurckFlow(V, F, 0.01)
    for _ in range(4):
        X = step(flow, None)
        r = np.linalg.norm(X, axis=1)
        np.testing.assert_allclose(np.cross(X, V), 0.0, atol=1e-13)
        np.testing.assert_allclose(r, r[0], rtol=1e-13)


def test_tangential_motion_relaxes_towards_the_reference_at_rate_one_over_alpha():
    """The harmonic map heat flow: a level-3 sphere whose points were slid along the
    sphere (smoothly, 0.066 on average) returns towards the reference positions
    (mean distance of the directions, 20 steps of 1e-4): about 10x faster with
    alpha = 0.1 than with alpha = 1 (measured decreases 4.06e-3 and 4.62e-4, ratio 8.8);
    cotan does not (4e-6, outwards)."""
    V, F = icosphere(3)
    slide = 0.08 * np.stack([np.sin(3 * V[:, 2]), np.cos(2 * V[:, 0]), np.sin(V[:, 1])], 1)
    slide -= V * (slide * V).sum(axis=1)[:, None]
    X0 = V + slide
    X0 /= np.linalg.norm(X0, axis=1)[:, None]

    def distance(flow):
        X = flow.vertices
        return np.linalg.norm(X / np.linalg.norm(X, axis=1)[:, None] - V, axis=1).mean()

    decrease = []
    for flow in (DeTurckFlow(V, F, 1e-4, alpha=0.1), DeTurckFlow(V, F, 1e-4, alpha=1.0),
                 CotanFlow(V, F, 1e-4)):
        flow.advance(X0.T.copy())
        start, stepper = distance(flow), Euler()
        for _ in range(20):
            stepper.step(flow, Solver(rtol=1e-12))
        decrease.append(start - distance(flow))
    assert decrease[0] > 3e-3 and 7 < decrease[0] / decrease[1] < 13, decrease
    assert abs(decrease[2]) < 2e-5


def test_invariant_under_rigid_motion_and_relabelling(noisy_sphere):
    agrees_under_rigid_motion_and_relabelling(DeTurckFlow, *noisy_sphere)


def test_sphere_is_second_order_in_space():
    """Table 3.1 setting, levels 1-3 (alpha = 0.1): 1.4464e-2, 3.3792e-3, 8.2416e-4."""
    table = level_sweep("deturck", "sphere", [1, 2, 3])
    assert (table["status"] == "ok").all()
    np.testing.assert_allclose(table["l2_error"], [1.4464e-2, 3.3792e-3, 8.2416e-4],
                               rtol=1e-3)
    assert np.all(table["eoc_l2_error"].to_numpy()[1:] > 2.0)


def test_catenoid_is_second_order_with_its_boundary_kept():
    """Largest radial error 3.513e-3, 8.66e-4 (BGN's to 0.1 %; cotan 3.437e-3,
    8.42e-4)."""
    reaches_the_catenoid_keeping_its_boundary("deturck", DeTurckFlow, [3.513e-3, 8.66e-4])


@pytest.mark.parametrize("alpha", [0.0, -1.0, np.inf, np.nan])
def test_bad_alpha_is_named(alpha):
    with pytest.raises(ValueError, match="alpha must be a positive finite number"):
        DeTurckFlow(*icosahedron(), 0.01, alpha=alpha)
