import numpy as np
import pytest
from conftest import cylinder, flat_lattice

from ddfv.t_vertices import cotangent_mean_curvature_vector, initial_t_vertices
from ddfv.topology import diamond_mesh
from mcfbench.geometry.spheres import icosphere


def test_exact_initialisation_lies_on_the_sphere():
    V, F = icosphere(2, 1.7)
    T = initial_t_vertices(V + 5.0, diamond_mesh(F), "exact") - 5.0
    np.testing.assert_allclose(np.linalg.norm(T, axis=1), 1.7, rtol=1e-12)


def test_paper_initialisation_approaches_the_sphere():
    gaps = []
    for level in (1, 2, 3):
        V, F = icosphere(level)
        T = initial_t_vertices(V, diamond_mesh(F), "paper")
        gaps.append(np.abs(np.linalg.norm(T, axis=1) - 1).max())
        bary = np.linalg.norm(V[F].mean(axis=1), axis=1)
        assert gaps[-1] < 0.25 * np.abs(bary - 1).max()   # far closer than barycentres
    assert gaps[0] > gaps[1] > gaps[2]


def test_paper_initialisation_keeps_flat_triangles_at_barycentre():
    V, F = flat_lattice(4, 4)
    mesh = diamond_mesh(F)
    np.testing.assert_allclose(initial_t_vertices(V, mesh, "paper"), V[F].mean(axis=1),
                               atol=1e-12)


def test_paper_initialisation_on_open_cylinder_ignores_boundary_vertices():
    V, F = cylinder(24, 6)
    T = initial_t_vertices(V, diamond_mesh(F), "paper")
    # the osculating sphere of a cylinder of radius 1 has radius 2/|h| = 2:
    # T moves outwards from the barycentre, by much less than the edge length
    r_bary = np.linalg.norm(V[F].mean(axis=1)[:, :2], axis=1)
    r_t = np.linalg.norm(T[:, :2], axis=1)
    assert np.all(r_t > r_bary) and np.all(r_t - r_bary < 0.01)


def test_cotangent_curvature_of_sphere():
    """h ~ -2 x; pointwise it is off by O(1) at the 12 valence-5 vertices."""
    V, F = icosphere(3)
    h = cotangent_mean_curvature_vector(V, F)
    assert np.einsum("ij,ij->i", h, V).mean() == pytest.approx(-2, rel=0.01)
    assert np.median(np.linalg.norm(h + 2 * V, axis=1)) < 0.05


def test_unknown_method():
    V, F = icosphere(0)
    with pytest.raises(ValueError, match="unknown T-vertex initialisation"):
        initial_t_vertices(V, diamond_mesh(F), "centroid")
