import numpy as np
import pytest
from conftest import bumpy_sphere, cylinder, flat_lattice
from reference import literal_system

from ddfv import kernels
from ddfv.assembly import Assembler, flux_coefficients
from ddfv.geometry import covolume_areas, diamond_geometry
from ddfv.t_vertices import initial_t_vertices
from ddfv.topology import diamond_mesh
from mcfbench.geometry.spheres import icosphere


def _state(V, F, t_init="paper", noise=0.0, seed=0):
    mesh = diamond_mesh(F, len(V))
    T = initial_t_vertices(V, mesh, t_init)
    T = T + noise * np.random.default_rng(seed).normal(size=T.shape)
    return mesh, T, diamond_geometry(mesh, V, T)


def test_flux_matches_metric_normal_and_derivatives():
    """alpha u - beta v = |gamma| (nu^lambda d_lambda phi + nu^mu d_mu phi), (2.3)-(2.8)."""
    rng = np.random.default_rng(3)
    for _ in range(50):
        Fa, Fb, T1, T2 = rng.normal(size=(4, 3))
        u, v = Fb - Fa, T2 - T1
        g = 0.25 * np.array([[(u - v) @ (u - v), (u - v) @ (u + v)],
                             [(u - v) @ (u + v), (u + v) @ (u + v)]])           # (2.3)
        J = np.linalg.norm(np.cross(u, v))
        nu = np.array([v @ v + u @ v, v @ v - u @ v]) / (np.linalg.norm(v) * J)  # (2.6)
        tangent = np.array([-1.0, 1.0])             # gamma^T: (1 - t, t)
        assert tangent @ g @ nu == pytest.approx(0, abs=1e-10)                  # orthogonal
        assert nu @ g @ nu == pytest.approx(1, rel=1e-10)                       # unit
        assert nu.sum() > 0            # outward: away from F_a along d_lambda + d_mu = u
        d_lambda, d_mu = (u - v) / 2, (u + v) / 2                               # (2.7)
        S = (Fa + Fb + T1 + T2) / 4
        gamma_t = np.linalg.norm(T1 - S) + np.linalg.norm(T2 - S)
        expected = gamma_t * (nu[0] * d_lambda + nu[1] * d_mu)
        mesh_geom = type("G", (), dict(
            gamma_t=gamma_t, gamma_f=1.0, J=J, uv=u @ v,
            len_u=np.linalg.norm(u), len_v=np.linalg.norm(v)))
        alpha, beta, _, _ = flux_coefficients(mesh_geom)
        np.testing.assert_allclose(alpha * u - beta * v, expected, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("make", [lambda: icosphere(1), lambda: bumpy_sphere(1)])
def test_assembly_matches_literal_transcription(make):
    V, F = make()
    mesh, T, geom = _state(V, F, noise=0.01)
    chi = np.concatenate(covolume_areas(mesh, geom))
    tau = 0.01
    A = Assembler(mesh).system(geom, chi, tau).toarray()
    np.testing.assert_allclose(A, literal_system(V, T, F, tau), rtol=1e-10, atol=1e-13)


@pytest.mark.parametrize("make", [lambda: bumpy_sphere(2), lambda: flat_lattice(5, 4)])
def test_row_sums_vanish(make):
    V, F = make()
    mesh, T, geom = _state(V, F, t_init="barycenter", noise=0.01)
    K = Assembler(mesh).stiffness(geom)
    scale = abs(K).sum(axis=1).max()
    assert abs(K.sum(axis=1)).max() < 1e-13 * scale
    A = Assembler(mesh).system(geom, np.concatenate(covolume_areas(mesh, geom)), 0.1)
    np.testing.assert_allclose(A.sum(axis=1), 1.0, atol=1e-12)


def test_affine_functions_are_exact_on_flat_lattice():
    V, F = flat_lattice(6, 5)
    mesh, T, geom = _state(V, F, t_init="barycenter")
    K = Assembler(mesh).stiffness(geom)
    X = np.concatenate([V, T])
    rng = np.random.default_rng(0)
    for _ in range(3):
        f = X @ rng.normal(size=3) + rng.normal()
        interior = np.r_[~mesh.boundary_vertices, np.ones(mesh.n_t, bool)]
        assert np.abs(K @ f)[interior].max() < 1e-12
    # a quadratic is not annihilated: the test can fail
    assert np.abs(K @ (X[:, 0] ** 2))[interior].max() > 0.1


def test_dirichlet_rows_are_identity():
    V, F = flat_lattice(4, 4)
    mesh, T, geom = _state(V, F, t_init="barycenter")
    A = Assembler(mesh).system(geom, np.concatenate(covolume_areas(mesh, geom)), 0.1)
    rows = np.flatnonzero(mesh.boundary_vertices)
    np.testing.assert_array_equal(A[rows].toarray(), np.eye(A.shape[0])[rows])


def test_discrete_laplacian_of_sphere_converges_to_mean_curvature():
    """Pointwise consistency is of low order on the irregular icosphere (as for
    the cotangent Laplacian); the flow itself converges at order 2 (test_sphere)."""
    errors = []
    for level in (2, 3, 4):
        V, F = icosphere(level)
        mesh, T, geom = _state(V, F, t_init="exact")
        chi = np.concatenate(covolume_areas(mesh, geom))
        X = np.concatenate([V, T])
        h = -(Assembler(mesh).stiffness(geom) @ X) / chi[:, None]
        errors.append(np.sqrt(np.sum(chi[:, None] * (h + 2 * X) ** 2) / 2))   # h = -2 x
    assert errors[2] < errors[1] < errors[0]
    assert np.log2(errors[0] / errors[1]) > 0.5 and np.log2(errors[1] / errors[2]) > 0.5


def _flux_loop_system(mesh, geom, chi, tau):
    """Dense ``I + tau diag(1/chi) K`` from the flux form, diamond by diamond:
    ``K`` collects minus the fluxes (module docstring of ddfv.assembly), the
    missing ``f_t2`` of a boundary diamond is ``f_a + f_b - f_t1``
    (Section 2.2.5) and boundary F-rows are rows of the identity."""
    n_f, n = mesh.n_f, mesh.n_unknowns
    K = np.zeros((n, n))
    for d, (a, b, t1, t2) in enumerate(mesh.diamonds):
        gt, gf, J = geom.gamma_t[d], geom.gamma_f[d], geom.J[d]
        lu, lv, uv = geom.len_u[d], geom.len_v[d], geom.uv[d]
        alpha, beta = gt * lv / J, gt * uv / (lv * J)              # (2.12)
        alpha_hat, beta_hat = gf * lu / J, gf * uv / (lu * J)      # (2.15)
        ta = n_f + t1
        # f_t2 as a combination of unknowns
        f_t2 = {n_f + t2: 1.0} if t2 >= 0 else {a: 1.0, b: 1.0, ta: -1.0}
        # flux_a = alpha (f_b - f_a) - beta (f_t2 - f_t1),
        # flux_t1 = alpha_hat (f_t2 - f_t1) - beta_hat (f_b - f_a)
        flux_a = {b: alpha, a: -alpha, ta: beta}
        flux_t1 = {ta: -alpha_hat, b: -beta_hat, a: beta_hat}
        for col, w in f_t2.items():
            flux_a[col] = flux_a.get(col, 0.0) - beta * w
            flux_t1[col] = flux_t1.get(col, 0.0) + alpha_hat * w
        for col, w in flux_a.items():
            K[a, col] -= w
            K[b, col] += w                                         # flux_b = -flux_a
        for col, w in flux_t1.items():
            K[ta, col] -= w
            if t2 >= 0:
                K[n_f + t2, col] += w                              # flux_t2 = -flux_t1
    A = np.eye(n) + tau / chi[:, None] * K
    dirichlet = np.flatnonzero(mesh.boundary_vertices)
    A[dirichlet] = np.eye(n)[dirichlet]
    return A


@pytest.mark.parametrize("make", [lambda: cylinder(10, 4), lambda: flat_lattice(4, 3),
                                  lambda: bumpy_sphere(1)])
def test_compiled_assembly_matches_flux_loop(make):
    V, F = make()
    mesh, T, geom = _state(V, F, t_init="barycenter", noise=0.02, seed=4)
    chi = np.concatenate(covolume_areas(mesh, geom))
    A = Assembler(mesh).system(geom, chi, 0.05)
    assert A.has_canonical_format                # sorted, no duplicate entries
    np.testing.assert_allclose(A.toarray(), _flux_loop_system(mesh, geom, chi, 0.05),
                               rtol=1e-12, atol=1e-14)


def test_flux_coefficients_are_the_compiled_formulas():
    rng = np.random.default_rng(11)
    values = rng.uniform(0.1, 2.0, size=(6, 50))
    values[5] -= 1.0                                       # u.v of either sign
    geom = type("G", (), dict(zip(("gamma_t", "gamma_f", "J", "len_u", "len_v", "uv"),
                                  values)))
    arrays = np.array(flux_coefficients(geom))
    compiled = np.array([kernels.flux_coefficients_kernel(*column) for column in values.T]).T
    np.testing.assert_array_equal(arrays, compiled)


def test_geometry_of_another_mesh_is_refused():
    V, F = icosphere(1)
    mesh, T, geom = _state(V, F)
    other_mesh, _, other_geom = _state(*icosphere(2))
    with pytest.raises(ValueError, match="gamma_t"):
        Assembler(mesh).stiffness(other_geom)
    with pytest.raises(ValueError, match="chi"):
        Assembler(mesh).system(geom, np.ones(other_mesh.n_unknowns), 0.1)


def _kernel_values(assembler, geom, scale, shift, threads, first_touch):
    """The values of :func:`kernels.system_kernel`: with ``first_touch`` from an array
    of NaN with the flagged slots (no entry may depend on what the array held), else
    summed into a zeroed array (identity set first) with the slots unflagged, as the
    kernel did before it flagged the first write into each entry."""
    from kept_factor.threads import for_threads

    if first_touch:
        data = np.full(assembler.nnz, np.nan)
        slots, untouched = assembler._first_touch(threads)
    else:
        data = np.zeros(assembler.nnz)
        data[assembler._diag] = shift
        slots, untouched = assembler._slots, np.zeros(0, np.uint32)
    factors = [np.asarray(getattr(geom, n)) for n in ("gamma_t", "gamma_f", "J", "len_u",
                                                      "len_v", "uv")]
    for_threads(kernels.system_kernel, threads)(
        assembler._inner, *factors, slots, assembler._rows,
        *assembler._mesh.diamond_blocks(threads), untouched, scale, shift, data)
    return data


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("make", [lambda: cylinder(10, 4), lambda: bumpy_sphere(1)])
def test_first_writes_give_the_zeroed_sums_bitwise(make, threads):
    """No zeroing pass: the flagged first write into each entry starts from
    what the zeroed array held, so the values are bitwise those of the sums into
    a zeroed array (boundary diamonds, the blocks of two threads); a vertex in
    no triangle keeps its identity row."""
    V, F = make()
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])          # a vertex in no triangle
    mesh, T, geom = _state(V, F, t_init="barycenter", noise=0.02, seed=4)
    assembler = Assembler(mesh)
    chi = np.concatenate(covolume_areas(mesh, geom))
    chi[mesh.n_f - 1] = 1.0                        # the lone vertex: no covolume
    scale = 0.05 / chi
    scale[np.r_[mesh.boundary_vertices, np.zeros(mesh.n_t, bool)]] = 0.0
    zeroed = _kernel_values(assembler, geom, scale, 1.0, threads, False)
    assert np.array_equal(_kernel_values(assembler, geom, scale, 1.0, threads, True), zeroed)
    A = assembler.system(geom, chi, 0.05, threads=threads)
    assert np.array_equal(A.data, zeroed)
    _, untouched = assembler._first_touch(threads)
    assert len(untouched) == 1 and A[mesh.n_f - 1, mesh.n_f - 1] == 1.0
    assert A[mesh.n_f - 1].nnz == 1
    K = assembler.stiffness(geom)                  # one thread
    assert np.array_equal(K.data, _kernel_values(
        assembler, geom, (~assembler._dirichlet).astype(float), 0.0, 1, False))
