import numpy as np
import pytest

from conftest import bumpy_sphere, flat_lattice
from ddfv.geometry import (covolume_areas, diamond_corners, diamond_geometry,
                           t_barycentric, triangle_areas, vertex_normals)
from ddfv.surfaces import icosphere
from ddfv.t_vertices import initial_t_vertices
from ddfv.topology import diamond_mesh


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
