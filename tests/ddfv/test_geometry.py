import numpy as np
import pytest
from conftest import bumpy_sphere, cylinder, flat_lattice

from ddfv.geometry import (
    covolume_areas,
    diamond_corners,
    diamond_geometry,
    t_barycentric,
    triangle_areas,
    vertex_normals,
)
from ddfv.t_vertices import initial_t_vertices
from ddfv.topology import DiamondMesh, diamond_mesh
from mcfbench.geometry.spheres import icosphere


def _random_state(seed=1):
    V, F = bumpy_sphere(1)
    mesh = diamond_mesh(F)
    rng = np.random.default_rng(seed)
    T = initial_t_vertices(V, mesh, "barycenter") + 0.02 * rng.normal(size=(mesh.n_t, 3))
    return mesh, V, T


def test_gram_formulas_match_cross_products():
    mesh, F, T = _random_state()
    g = diamond_geometry(mesh, F, T)
    Fa, Fb, T1, T2 = (c.T for c in diamond_corners(mesh, F, T))
    S = (Fa + Fb + T1 + T2) / 4
    area = lambda p, q, r: 0.5 * np.linalg.norm(np.cross(q - p, r - p), axis=1)
    np.testing.assert_allclose(g.J, np.linalg.norm(np.cross(Fb - Fa, T2 - T1), axis=1), rtol=1e-10)
    np.testing.assert_allclose(g.quarters, [area(Fa, T1, S), area(Fa, S, T2),
                                            area(Fb, T1, S), area(Fb, S, T2)], rtol=1e-8)
    np.testing.assert_allclose(g.gamma_t, np.linalg.norm(T1 - S, axis=1)
                               + np.linalg.norm(T2 - S, axis=1), rtol=1e-12)
    np.testing.assert_allclose(g.gamma_f, np.linalg.norm(Fa - S, axis=1)
                               + np.linalg.norm(Fb - S, axis=1), rtol=1e-12)
    np.testing.assert_allclose(g.e.T, (Fa + Fb - T1 - T2) / 4, atol=1e-15)


def test_covolume_families_tile_the_same_area():
    mesh, F, T = _random_state()
    chi_f, chi_t = covolume_areas(mesh, diamond_geometry(mesh, F, T))
    assert chi_f.min() > 0 and chi_t.min() > 0
    assert chi_f.sum() == pytest.approx(chi_t.sum(), rel=1e-12)


def test_covolumes_of_flat_lattice_cover_it_exactly():
    m, k = 6, 5
    V, F = flat_lattice(m, k)
    mesh = diamond_mesh(F)
    T = initial_t_vertices(V, mesh, "barycenter")
    chi_f, chi_t = covolume_areas(mesh, diamond_geometry(mesh, V, T))
    assert chi_f.sum() == pytest.approx(m * k, rel=1e-12)
    assert chi_t.sum() == pytest.approx(m * k, rel=1e-12)
    # an interior vertex of this lattice owns exactly one unit of area
    interior = ~mesh.boundary_vertices
    np.testing.assert_allclose(chi_f[interior], 1.0, rtol=1e-12)


def test_t_barycentric_coordinates():
    V, F = icosphere(1)
    tri = V[F]
    normal = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    g = tri.mean(axis=1)
    np.testing.assert_allclose(t_barycentric(V, g + 0.3 * normal, F), 1 / 3, atol=1e-12)
    np.testing.assert_allclose(t_barycentric(V, tri[:, 1], F), np.tile([0, 1, 0], (len(F), 1)),
                               atol=1e-12)
    outside = 2 * tri[:, 2] - g   # beyond vertex 2
    lam = t_barycentric(V, outside, F)
    assert np.all(lam.min(axis=1) < 0)
    np.testing.assert_allclose(lam.sum(axis=1), 1.0)


def test_vertex_normals_of_sphere_are_radial():
    V, F = icosphere(3)
    mesh = diamond_mesh(F)
    T = initial_t_vertices(V, mesh, "exact")
    N = vertex_normals(mesh, diamond_geometry(mesh, V, T)).T
    X = np.concatenate([V, T])
    cosine = np.einsum("ij,ij->i", N, X / np.linalg.norm(X, axis=1, keepdims=True))
    assert np.abs(np.abs(cosine) - 1).max() < 1e-3
    assert np.all(np.sign(cosine) == np.sign(cosine[0]))   # one orientation


def test_triangle_areas_of_lattice():
    V, F = flat_lattice(3, 2)
    np.testing.assert_allclose(triangle_areas(V, F), 0.5)


def _random_diamonds(seed, n_f=30, n_t=20, n_d=80, boundary=0.25):
    """Random corners and random diamonds (a quarter of them boundary diamonds)."""
    rng = np.random.default_rng(seed)
    a = rng.integers(n_f, size=n_d)
    b = (a + 1 + rng.integers(n_f - 1, size=n_d)) % n_f
    t1 = rng.integers(n_t, size=n_d)
    t2 = (t1 + 1 + rng.integers(n_t - 1, size=n_d)) % n_t
    t2[rng.random(n_d) < boundary] = -1
    mesh = DiamondMesh(n_f=n_f, faces=np.zeros((n_t, 3), dtype=np.int64),
                       diamonds=np.asfortranarray(np.column_stack([a, b, t1, t2])),
                       halfedges=np.zeros((n_t, 3), dtype=np.int64))
    return mesh, rng.normal(size=(n_f, 3)), rng.normal(size=(n_t, 3))


def _loop_geometry(mesh, F, T, dual_length):
    """Each field of DiamondGeometry, the covolumes and the vertex normals,
    diamond by diamond from the corners (cross products, no Gram matrix)."""
    norm, cross = np.linalg.norm, np.cross
    area = lambda p, q, r: 0.5 * norm(cross(q - p, r - p))
    n_d = len(mesh.diamonds)
    out = {name: np.zeros(n) for name, n in (("u", (3, n_d)), ("v", (3, n_d)), ("e", (3, n_d)),
                                             ("quarters", (4, n_d)))}
    out.update({name: np.zeros(n_d) for name in ("len_u", "len_v", "J", "uv", "gamma_t",
                                                 "gamma_f")})
    chi_f, chi_t = np.zeros(mesh.n_f), np.zeros(mesh.n_t)
    normals = np.zeros((mesh.n_unknowns, 3))
    for d, (a, b, t1, t2) in enumerate(mesh.diamonds):
        Fa, Fb, T1 = F[a], F[b], T[t1]
        T2 = T[t2] if t2 >= 0 else Fa + Fb - T1                   # Section 2.2.5
        S = (Fa + Fb + T1 + T2) / 4
        u, v = Fb - Fa, T2 - T1
        quarters = [area(Fa, T1, S), area(Fa, S, T2) if t2 >= 0 else 0.0,
                    area(Fb, T1, S), area(Fb, S, T2) if t2 >= 0 else 0.0]
        broken = dual_length == "broken"
        for name, value in (("u", u), ("v", v), ("e", (Fa + Fb - T1 - T2) / 4),
                            ("len_u", norm(u)), ("len_v", norm(v)), ("J", norm(cross(u, v))),
                            ("uv", u @ v), ("quarters", quarters),
                            ("gamma_t", norm(T1 - S) + norm(T2 - S) if broken else norm(v)),
                            ("gamma_f", norm(Fa - S) + norm(Fb - S) if broken else norm(u))):
            out[name][..., d] = value
        chi_f[a] += quarters[0] + quarters[1]
        chi_f[b] += quarters[2] + quarters[3]
        chi_t[t1] += quarters[0] + quarters[2]
        rows = [a, b, mesh.n_f + t1] + ([mesh.n_f + t2] if t2 >= 0 else [])
        for i in rows:
            normals[i] += cross(u, v)
        if t2 >= 0:
            chi_t[t2] += quarters[1] + quarters[3]
    normals /= norm(normals, axis=1, keepdims=True)
    return out, chi_f, chi_t, normals.T


@pytest.mark.parametrize("dual_length", ["broken", "chord"])
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_geometry_matches_loop_over_random_diamonds(seed, dual_length):
    mesh, F, T = _random_diamonds(seed)
    g = diamond_geometry(mesh, F, T, dual_length)
    expected, chi_f, chi_t, normals = _loop_geometry(mesh, F, T, dual_length)
    for name, value in expected.items():
        got = getattr(g, name)
        assert got.shape == value.shape, name
        # Gram-matrix areas of thin triangles lose digits to cancellation (1e-10 absolute)
        np.testing.assert_allclose(got, value, rtol=1e-10, atol=1e-10, err_msg=name)
    got_f, got_t = covolume_areas(mesh, g)
    np.testing.assert_allclose(got_f, chi_f, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(got_t, chi_t, rtol=1e-10, atol=1e-10)
    np.testing.assert_allclose(vertex_normals(mesh, g), normals, rtol=1e-10, atol=1e-12)


def test_compiled_geometry_matches_loop_on_open_mesh():
    V, F = cylinder(12, 4)
    mesh = diamond_mesh(F, len(V))
    rng = np.random.default_rng(5)
    T = initial_t_vertices(V, mesh, "barycenter") + 0.05 * rng.normal(size=(mesh.n_t, 3))
    assert mesh.has_boundary
    g = diamond_geometry(mesh, V, T)
    expected, chi_f, chi_t, normals = _loop_geometry(mesh, V, T, "broken")
    for name, value in expected.items():
        np.testing.assert_allclose(getattr(g, name), value, rtol=1e-10, atol=1e-12, err_msg=name)
    np.testing.assert_allclose(np.concatenate(covolume_areas(mesh, g)),
                               np.concatenate([chi_f, chi_t]), rtol=1e-12)
    np.testing.assert_allclose(vertex_normals(mesh, g), normals, rtol=1e-10, atol=1e-12)


def test_results_do_not_depend_on_memory_layout():
    """Strided views of one (3, n) state, as a flow passes them, give the
    same bits as contiguous copies."""
    mesh, F, T = _random_state(3)
    X = np.ascontiguousarray(np.concatenate([F, T]).T)
    Fv, Tv = X[:, :mesh.n_f].T, X[:, mesh.n_f:].T
    assert not Fv.flags.c_contiguous and not Tv.flags.c_contiguous
    g, gv = diamond_geometry(mesh, F, T), diamond_geometry(mesh, Fv, Tv)
    for name in g.__dataclass_fields__:
        np.testing.assert_array_equal(getattr(g, name), getattr(gv, name), err_msg=name)
    np.testing.assert_array_equal(t_barycentric(F, T, mesh.faces),
                                  t_barycentric(Fv, Tv, mesh.faces))
    faces_c = np.ascontiguousarray(mesh.faces, dtype=np.int32)
    np.testing.assert_array_equal(t_barycentric(F, T, mesh.faces), t_barycentric(F, T, faces_c))


def test_t_barycentric_matches_least_squares_projection():
    rng = np.random.default_rng(7)
    F = rng.normal(size=(12, 3))
    faces = np.array([rng.choice(12, 3, replace=False) for _ in range(40)])
    T = rng.normal(size=(40, 3))
    lam = t_barycentric(F, T, faces)
    for t, f in enumerate(faces):
        p = F[f]
        l12 = np.linalg.lstsq(np.column_stack([p[1] - p[0], p[2] - p[0]]), T[t] - p[0],
                              rcond=None)[0]
        np.testing.assert_allclose(lam[t], [1 - l12.sum(), *l12], rtol=1e-9, atol=1e-12)


def test_out_of_range_indices_raise_instead_of_reading_memory():
    mesh, F, T = _random_diamonds(0)
    for column, index in ((0, mesh.n_f), (1, -1), (2, mesh.n_t), (3, -2), (3, mesh.n_t)):
        bad = mesh.diamonds.copy()
        bad[5, column] = index                     # only t2 may be -1
        bad_mesh = DiamondMesh(n_f=mesh.n_f, faces=mesh.faces, diamonds=bad,
                               halfedges=mesh.halfedges)
        with pytest.raises(IndexError):
            diamond_geometry(bad_mesh, F, T)
    with pytest.raises(IndexError):
        t_barycentric(F, T[:2], np.array([[0, 1, 2], [0, 1, len(F)]]))
    with pytest.raises(IndexError):
        t_barycentric(F, T[:2], np.array([[0, 1, 2], [0, -1, 2]]))
    with pytest.raises(ValueError, match="T must have shape"):
        diamond_geometry(mesh, F, T[:-1])


@pytest.mark.parametrize("threads", [1, 2])
def test_covolumes_in_the_geometry_pass_are_those_of_covolume_areas(threads):
    V, F = icosphere(3)
    mesh = diamond_mesh(F)
    T = V[F].mean(axis=1) + np.random.default_rng(5).normal(scale=0.01, size=(len(F), 3))
    separate = diamond_geometry(mesh, V, T)
    chi = np.empty(mesh.n_unknowns)
    fused = diamond_geometry(mesh, V, T, threads=threads, vectors=False, covolumes=chi)
    chi_f, chi_t = covolume_areas(mesh, separate)
    if threads == 1:       # the same sums in the same order
        np.testing.assert_array_equal(chi, np.r_[chi_f, chi_t])
    np.testing.assert_allclose(chi, np.r_[chi_f, chi_t], rtol=1e-14)
    assert fused.quarters is None and fused.u is None and fused.e is None
    for name in ("J", "uv", "len_u", "len_v", "gamma_t", "gamma_f"):
        np.testing.assert_array_equal(getattr(fused, name), getattr(separate, name))
    with pytest.raises(ValueError, match="covolumes"):
        diamond_geometry(mesh, V, T, covolumes=np.empty(3))
