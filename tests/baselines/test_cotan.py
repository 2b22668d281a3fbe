"""The cotangent baseline (baselines/cotan.py) and its shared assembly."""

from functools import partial

import igl
import numpy as np
import pytest
import scipy.sparse as sp
from conftest import approaches_the_catenoid, cylinder, flat_lattice, table_3_1_error

from baselines import cotan
from baselines.cotan import CotanFlow
from baselines.laplacian import MASS_TYPES, CotanAssembler, cotangent_laplacian, lumped_mass
from baselines.mesh import edge_mesh
from mcfbench.geometry.exact import eoc
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.integrators import Euler
from mcfbench.running.solver import Solver

EXACT = Solver(method="direct", rtol=1e-12)


def rigid_motion():
    Q, _ = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))
    return Q, np.array([0.3, -1.2, 2.0])


# -- operators ---------------------------------------------------------------

@pytest.mark.parametrize("mass", ["barycentric", "voronoi"])
def test_compiled_assembly_matches_igl(noisy_sphere, mass):
    V, F = noisy_sphere
    g = CotanAssembler(edge_mesh(F, len(V)), mass).geometry(V)
    L = CotanAssembler(edge_mesh(F, len(V))).laplacian(g.L_data)
    np.testing.assert_allclose(L.toarray(), -igl.cotmatrix(V, F).toarray(), rtol=0, atol=2e-15)
    np.testing.assert_allclose(g.mass, igl.massmatrix(V, F, MASS_TYPES[mass]).diagonal(),
                               rtol=1e-13)


def test_the_geometry_of_a_flows_state_view_is_that_of_its_copy(noisy_sphere):
    """The flows pass (n, 3) views of their (3, n) states (Fortran order), assembled as
    they are: bitwise the geometry of a C-ordered copy."""
    V, F = noisy_sphere
    X = np.ascontiguousarray(V.T)
    asm = CotanAssembler(edge_mesh(F, len(V)), "voronoi")
    view, copy = asm.geometry(X.T), asm.geometry(X.T.copy())
    for name in ("L_data", "mass", "area_vectors"):
        np.testing.assert_array_equal(getattr(view, name), getattr(copy, name))


def test_voronoi_mass_of_an_obtuse_triangle():
    # Meyer et al. 2003: |T|/2 at the obtuse corner, |T|/4 at the others
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.2, 0.1, 0]])
    F = np.array([[0, 1, 2]])
    m = CotanAssembler(edge_mesh(F, 3), "voronoi").geometry(V).mass
    np.testing.assert_allclose(m, 0.05 * np.array([0.25, 0.25, 0.5]), rtol=1e-14)


def test_laplacian_is_symmetric_with_zero_row_sums_and_positive(noisy_sphere):
    V, F = noisy_sphere
    L = CotanFlow(V, F, 0.01).laplacian()
    assert abs(L - L.T).max() < 1e-15
    assert np.abs(np.asarray(L.sum(axis=1))).max() < 1e-13
    assert L.diagonal().min() > 0
    # positive semi-definite, kernel = constants: smallest eigenvalues 0, then > 0
    eig = np.linalg.eigvalsh(L.toarray())
    assert abs(eig[0]) < 1e-12 and eig[1] > 0.1   # measured eig[1] = 0.152


@pytest.mark.parametrize("mass", ["barycentric", "voronoi"])
def test_mass_is_positive_and_sums_to_the_area(noisy_sphere, mass):
    V, F = noisy_sphere
    flow = CotanFlow(V, F, 0.01, mass=mass)
    area = 0.5 * igl.doublearea(V, F).sum()
    assert flow.l2_weights.min() > 0
    assert flow.l2_weights.sum() == pytest.approx(area, rel=1e-14)


def test_laplacian_annihilates_affine_functions_on_a_flat_mesh():
    V, F = flat_lattice(6, 5)
    V = V + np.c_[np.random.default_rng(1).uniform(-0.2, 0.2, (len(V), 2)), np.zeros(len(V))]
    flow = CotanFlow(V, F, 0.01)
    u = 0.7 * V[:, 0] - 1.3 * V[:, 1] + 2.0
    Lu = flow.laplacian() @ u
    interior = ~flow.fixed
    assert interior.sum() == 20
    assert np.abs(Lu[interior]).max() < 1e-13
    assert np.abs(Lu[~interior]).max() > 0.1  # not at the boundary (measured 1.48)


@pytest.mark.parametrize("mass", ["barycentric", "voronoi"])
def test_system_matrix_is_row_scaled_c1(noisy_sphere, mass):
    V, F = noisy_sphere
    tau = 0.003
    expected = np.eye(len(V)) + tau * cotangent_laplacian(V, F).toarray() / \
        lumped_mass(V, F, mass)[:, None]
    for assembly in cotan.ASSEMBLIES:
        A, b = CotanFlow(V, F, tau, mass=mass, assembly=assembly).system()
        np.testing.assert_allclose(A.toarray(), expected, rtol=0, atol=1e-13)
        np.testing.assert_array_equal(b, V.T)


def test_matrices_of_the_pattern_share_it_and_keep_their_own_values(noisy_sphere):
    """:meth:`CotanAssembler.csr` (a shallow copy of one matrix of the pattern): each
    matrix is scipy's CSR of its values, and a later one does not change an earlier."""
    V, F = noisy_sphere
    assembler = CotanAssembler(edge_mesh(F, len(V)))
    g, h = assembler.geometry(V), assembler.geometry(1.5 * V + 0.1)
    A, B = assembler.laplacian(g.L_data), assembler.laplacian(h.L_data)
    p = assembler.pattern
    for M, data in ((A, g.L_data), (B, h.L_data)):
        expected = sp.csr_matrix((data.copy(), p.indices, p.indptr), shape=p.shape)
        assert type(M) is type(expected) and M.indices.dtype == expected.indices.dtype
        assert M.data is data and (M != expected).nnz == 0
    assert A.indices is B.indices and not np.array_equal(A.data, B.data)
    np.testing.assert_allclose(A.toarray(), -igl.cotmatrix(V, F).toarray(), rtol=0, atol=2e-15)


def test_dirichlet_rows_are_identity():
    V, F = cylinder(12, 4)
    flow = CotanFlow(V, F, 0.01)
    fixed = flow.fixed
    assert fixed.sum() == 24 and np.all(np.abs(np.abs(V[fixed, 2]) - 0.5) < 1e-15)
    A = flow.system()[0].toarray()
    np.testing.assert_array_equal(A[fixed], np.eye(len(V))[fixed])
    np.testing.assert_allclose(CotanFlow(V, F, 0.01, assembly="igl").system()[0].toarray(), A,
                               rtol=0, atol=1e-14)


# -- stepping ----------------------------------------------------------------

def test_one_step_is_invariant_under_rigid_motions(noisy_sphere):
    V, F = noisy_sphere
    Q, shift = rigid_motion()
    for mass in ("barycentric", "voronoi"):
        a, b = CotanFlow(V, F, 0.01, mass=mass), CotanFlow(V @ Q.T + shift, F, 0.01, mass=mass)
        Euler().step(a, EXACT)
        Euler().step(b, EXACT)
        np.testing.assert_allclose(b.vertices, a.vertices @ Q.T + shift, rtol=0, atol=1e-10)


def test_assemblies_agree():
    V, F = icosphere(2)
    a = simulate(CotanFlow(V, F, 0.01), 8, solver=Solver())
    b = simulate(CotanFlow(V, F, 0.01, assembly="igl"), 8, solver=Solver())
    np.testing.assert_allclose(a.frames["vertices"], b.frames["vertices"], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.iterations, b.iterations)


def test_warm_start_and_state_handling():
    V, F = icosphere(1)
    flow = CotanFlow(V, F, 0.01)
    seen = []

    def solve(A, b, x0):
        seen.append(x0.copy())
        return Solver()(A, b, x0)

    stepper = Euler()
    stepper.step(flow, solve)
    X1 = flow.X.copy()
    stepper.step(flow, solve)
    np.testing.assert_array_equal(seen[0], V.T)             # X^0 at the first step
    np.testing.assert_array_equal(seen[1], 2 * X1 - V.T)    # 2 X^1 - X^0
    assert flow.n == 2 and flow.X.shape == (3, len(V)) and not flow.X.flags.writeable
    frame = flow.frame()
    assert set(frame) == {"vertices"} and not np.shares_memory(frame["vertices"], flow.X)


def test_failed_solve_propagates_and_keeps_the_state():
    V, F = icosphere(1)
    flow = CotanFlow(V, F, 0.01)

    def broken(A, b, x0):
        raise RuntimeError("no convergence")

    with pytest.raises(RuntimeError, match="no convergence"):
        Euler().step(flow, broken)
    assert flow.n == 0
    np.testing.assert_array_equal(flow.vertices, V)


def test_sphere_errors_and_eoc_levels_1_to_3():
    # Table 3.1 setting; the errors are those of the committed implementation
    # before the refactoring (identical to 1e-11, same iteration counts)
    expected = {"barycentric": ([1.4463591e-2, 3.3984786e-3, 8.2795681e-4], [4, 26, 96]),
                "voronoi": ([1.4196975e-2, 3.2972176e-3, 8.0382723e-4], [2, 23, 65])}
    for mass, (errors, iterations) in expected.items():
        runs = [table_3_1_error(partial(CotanFlow, mass=mass), level) for level in (1, 2, 3)]
        np.testing.assert_allclose([e for e, _ in runs], errors, rtol=1e-6)
        assert [int(t.iterations.sum()) for _, t in runs] == pytest.approx(iterations, abs=2)
        orders = eoc([e for e, _ in runs])[1:]
        assert np.all((orders > 2.0) & (orders < 2.15)), orders   # 2.09, 2.04 / 2.11, 2.04


def test_open_cylinder_keeps_its_boundary_and_approaches_the_catenoid():
    # R = 1, h = 0.5: steady state r(z) = a cosh(z/a), a = 0.84834. 24 x 8
    # quads, tau = 0.005: measured neck 0.8725 (t = 0.25), 0.8465 (t = 0.75),
    # 0.8456 (t = 1: converged; the discrete catenoid lies 0.3 % inside)
    V, F = cylinder(24, 8)
    flow = CotanFlow(V, F, 0.005)
    traj = simulate(flow, 200, solver=Solver(), save_every=50)
    assert traj.status == "ok", traj.message
    X = traj.frames["vertices"]
    for frame in X:
        np.testing.assert_array_equal(frame[flow.fixed], V[flow.fixed])
    approaches_the_catenoid(X)


# -- defects and arguments ---------------------------------------------------

def test_defects():
    V, F = icosphere(2)
    assert CotanFlow(V, F, 0.01).defects() == []
    bad = V.copy()
    bad[5] = np.nan
    [(status, detail)] = CotanFlow(bad, F, 0.01).defects()
    assert status == "degenerated" and "vertex 5" in detail
    flat = V.copy()
    a, b, c = F[7]
    flat[c] = 0.5 * (flat[a] + flat[b])      # triangle 7 collapses to a segment
    [(status, detail)] = CotanFlow(flat, F, 0.01).defects()
    assert status == "degenerated" and "triangle 7" in detail
    # fold: vertex k moved past its neighbour j; the two triangles at the
    # edge kj (10 and 11) flip over (cosine -0.999), nothing else
    flow = CotanFlow(V, F, 0.01)
    k, j = F[11, 0], F[11, 1]
    flow._X = flow._X.copy()
    flow._X[:, k] = V[j] + 0.3 * (V[j] - V[k])
    flow.__dict__.pop("geometry", None)
    flow.__dict__.pop("_triangle_checks", None)
    [(status, detail)] = flow.defects()
    assert status == "inverted" and "2 triangle(s) inverted" in detail
    assert detail.startswith("triangle 11 flipped") and "cosine -0.999" in detail


@pytest.mark.parametrize("options, message", [
    (dict(tau=0.0), "tau must be a positive"),
    (dict(tau=float("inf")), "tau must be a positive"),
    (dict(tau=float("nan")), "tau must be a positive"),
    (dict(mass="full"), "unknown mass"),
    (dict(assembly="eigen"), "unknown assembly"),
])
def test_bad_parameters(options, message):
    V, F = icosphere(1)
    with pytest.raises(ValueError, match=message):
        CotanFlow(V, F, **{"tau": 0.01, **options})


def test_registry_entries():
    from mcfbench.running.schemes import get_scheme

    V, F = icosphere(1)
    for name, mass in (("cotan", "barycentric"), ("cotan-voronoi", "voronoi")):
        flow = get_scheme(name).make(V, F, 0.01)
        assert isinstance(flow, CotanFlow) and flow.mass_type == mass
