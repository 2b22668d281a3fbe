"""No compiled kernel of baselines/ divides by zero (issue #24): a zero-area
triangle is reported (count and index returned to Python), never raised."""

import numpy as np
import pytest

from baselines import kernels, tangential_kernels
from baselines.bgn import BGNFlow
from baselines.cotan import CotanFlow
from baselines.laplacian import CotanAssembler
from baselines.mesh import edge_mesh
from mcfbench.running.driver import simulate
from mcfbench.running.solver import Solver

# unit cube, 12 triangles, outward orientation
CUBE_V = np.array([[0., 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                   [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
CUBE_F = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
                   [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])


def flattened_tetrahedron():
    """Tetrahedron with triangle 1 = (0, 3, 1) of zero area (vertex 3 on edge 01)."""
    V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0, 0]])
    F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    return V, F


@pytest.mark.parametrize("mass", ["barycentric", "voronoi"])
def test_cotan_geometry_reports_a_zero_area_triangle(mass):
    V, F = flattened_tetrahedron()
    g = CotanAssembler(edge_mesh(F, 4), mass).geometry(V)
    assert (g.degenerate, g.first_degenerate) == (1, 1)
    assert np.all(np.isfinite(g.L_data)) and np.all(np.isfinite(g.mass))
    # the three other triangles still contribute: the mass sums to their area
    # ((0,1,2): 0.5, (0,2,3): 0.25, (1,3,2): 0.25)
    assert g.mass.sum() == pytest.approx(1.0, rel=1e-14)


def test_cotan_geometry_reports_non_finite_coordinates():
    V, F = flattened_tetrahedron()
    V[2] = np.nan
    g = CotanAssembler(edge_mesh(F, 4)).geometry(V)
    # the three triangles at vertex 2 (NaN area) and the flat triangle 1
    assert g.degenerate == 4 and g.first_degenerate == 0


def test_vertex_normals_and_systems_with_a_bare_vertex():
    # every triangle collapsed to the origin: zero mass, zero weights
    V, F = np.zeros((4, 3)), flattened_tetrahedron()[1]
    omega = np.empty((4, 3))
    assert kernels.vertex_normals(F, np.zeros((4, 3)), 4, omega) == 4
    assert np.all(omega == 0.0)
    asm = CotanAssembler(edge_mesh(F, 4))
    g = asm.geometry(V)
    assert g.degenerate == 4 and np.all(g.mass == 0.0)
    p = asm.pattern
    data = np.empty(p.nnz)
    fixed = np.zeros(4, dtype=bool)
    assert kernels.row_scaled_system(g.L_data, p.indptr, p.diag_slots, g.mass, 0.1, fixed,
                                     data) == 4
    np.testing.assert_array_equal(asm.csr(data).toarray(), np.eye(4))   # vertices stay
    n, nnz = 4, p.nnz
    A = np.empty(3 * (nnz + 2 * n))
    b = np.empty((3, n))
    X = np.arange(12.0).reshape(3, 4)
    for alpha in (0.0, 0.3):                                 # BGN's, DeTurck's Omega
        assert kernels.bgn_system(g.L_data, p.indptr, p.diag_slots, g.mass, omega, X, 0.1,
                                  fixed, True, alpha, A, b) == 4
        np.testing.assert_allclose(b, X, rtol=2e-16 if alpha else 0.0, atol=0.0)
    alpha = np.empty((4, 3))
    assert tangential_kernels.vertex_gradients(V, F, np.arange(4.0), alpha) == (4, 0)
    assert np.all(alpha == 0.0)


def test_collapsing_cube_ends_degenerated_naming_the_triangle():
    # `python -m mcfbench run cube.obj --scheme cotan --tau-edge 0.1 --steps 10`:
    # tau = 0.1 x (mean edge)^2; measured: all 12 triangles reach zero area at
    # step 6 (t = 0.777) and used to raise ZeroDivisionError in cotan_geometry. The
    # driver's own collapse check (the whole component) ends it at step 4 first:
    # switched off here, so that the scheme's check of its triangles is what ends it
    edges = edge_mesh(CUBE_F, 8).edges
    tau = 0.1 * np.mean(np.linalg.norm(CUBE_V[edges[:, 0]] - CUBE_V[edges[:, 1]], axis=1)) ** 2
    traj = simulate(CotanFlow(CUBE_V, CUBE_F, tau), 10, solver=Solver(method="direct"),
                    collapse=False)
    assert traj.status == "degenerated"
    assert traj.steps_done == 6
    assert "12 triangle(s) of zero area" in traj.message and "triangle 0" in traj.message


@pytest.mark.parametrize("flow_class", [CotanFlow, BGNFlow])
def test_defects_of_a_state_with_a_zero_area_triangle(flow_class):
    V, F = flattened_tetrahedron()
    flow = flow_class(np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0], [0.3, 0.3, 0.8]]), F, 0.01)
    flow._X = np.ascontiguousarray(V.T)
    flow.__dict__.pop("geometry", None)
    flow.__dict__.pop("_triangle_checks", None)
    [(status, detail)] = flow.defects()
    assert status == "degenerated" and "triangle 1" in detail
    flow.system()                                   # assembles without raising


def test_gradient_norm_weights_skip_a_zero_area_triangle():
    """KLL's ``|A|^2`` weights: the flat triangle 1 adds nothing and is counted; the
    others give ``|grad u|^2 = 2`` for ``u = (x, y, 0)`` on the plane z = 0 (area 1)."""
    V, F = flattened_tetrahedron()
    u = V * [1.0, 1.0, 0.0]
    w, squared = np.empty(4), np.empty(4)
    assert tangential_kernels.gradient_norm_weights(V, F, u, w, squared) == 1
    assert squared[1] == 0.0 and np.allclose(squared[[0, 2, 3]], 2.0, rtol=1e-14)
    assert w.sum() == pytest.approx(2.0, rel=1e-14)
    V[2] = np.nan
    assert tangential_kernels.gradient_norm_weights(V, F, u, w, squared) == 4
    assert np.all(w == 0.0)
