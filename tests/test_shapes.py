"""Initial surfaces of Section 3 (ddfv/shapes.py)."""

import numpy as np
import pytest

from ddfv import simulate
from ddfv.diagnostics import MeshQuality
from ddfv.shapes import SHAPES, bumpy_sphere, catenoid_waist, cylinder, hemisphere, make_shape
from ddfv.topology import diamond_mesh

# name -> (n_F, n_T, number of boundary edges, Euler characteristic) at the defaults
EXPECTED = {
    "sphere": (642, 1280, 0, 2),
    "bumpy_sphere": (642, 1280, 0, 2),
    "cymling": (642, 1280, 0, 2),
    "cylinder": (216, 384, 48, 0),
    "hemisphere": (331, 600, 60, 1),
}


def normals(V, F):
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_registry_lists_every_generator():
    assert set(SHAPES) == set(EXPECTED)


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_generator_gives_a_valid_mesh_of_the_stated_size(name):
    V, F = SHAPES[name]()
    n_f, n_t, n_boundary, euler = EXPECTED[name]
    assert V.shape == (n_f, 3) and V.dtype == float
    assert F.shape == (n_t, 3) and np.issubdtype(F.dtype, np.integer)
    assert np.isfinite(V).all()
    mesh = diamond_mesh(F, len(V))   # manifold, consistently oriented, no unused vertex
    assert int(mesh.boundary.sum()) == n_boundary
    assert n_f - len(mesh.diamonds) + n_t == euler
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    assert area.min() > 0.05 * area.mean()


@pytest.mark.parametrize("name", ["sphere", "bumpy_sphere", "cymling", "hemisphere"])
def test_normals_point_away_from_the_centre(name):
    V, F = SHAPES[name]()
    centroid = V[F].mean(axis=1)
    assert (np.einsum("ij,ij->i", normals(V, F), centroid) > 0).all()


def test_cylinder_normals_point_away_from_the_axis():
    V, F = cylinder()
    radial = V[F].mean(axis=1) * [1.0, 1.0, 0.0]
    assert (np.einsum("ij,ij->i", normals(V, F), radial) > 0).all()


def test_nv_of_the_paper():
    """n_V = n_F + n_T: 1922 (bumpy sphere, cymling), 600 (cylinder)."""
    for name, n_v in (("bumpy_sphere", 1922), ("cymling", 1922), ("cylinder", 600)):
        V, F = SHAPES[name]()
        assert len(V) + len(F) == n_v


def test_cylinder_boundary_is_two_circles():
    R, h = 1.3, 0.4
    V, F = cylinder(radius=R, half_height=h)
    mesh = diamond_mesh(F, len(V))
    B = V[mesh.boundary_vertices]
    assert len(B) == 48
    np.testing.assert_allclose(np.hypot(B[:, 0], B[:, 1]), R, rtol=1e-12)
    np.testing.assert_allclose(np.abs(B[:, 2]), h, rtol=1e-12)
    np.testing.assert_allclose(np.hypot(V[:, 0], V[:, 1]), R, rtol=1e-12)


def test_hemisphere_boundary_is_the_equator():
    V, F = hemisphere(rings=7, radius=2.0)
    mesh = diamond_mesh(F, len(V))
    assert (len(V), len(F)) == (1 + 3 * 7 * 8, 6 * 49)
    B = V[mesh.boundary_vertices]
    assert len(B) == 6 * 7
    np.testing.assert_allclose(np.linalg.norm(V, axis=1), 2.0, rtol=1e-12)
    assert (B[:, 2] == 0).all() and (V[~mesh.boundary_vertices, 2] > 0).all()


def test_bumpy_sphere_radius_formula():
    centres = np.array([[0.0, 0.0, 1.0]])
    V, _ = bumpy_sphere(level=2, amplitude=0.2, width=0.3, centres=centres)
    r = np.linalg.norm(V, axis=1)
    d = V / r[:, None]
    expected = 1.0 + 0.2 * np.exp(-np.sum((d - centres) ** 2, axis=1) / (2 * 0.3**2))
    np.testing.assert_allclose(r, expected, rtol=1e-12)


def test_cymling_is_flat_with_a_scalloped_rim():
    V, _ = make_shape("cymling", flattening=0.4, lobes=9, wave=0.1)
    assert np.abs(V[:, 2]).max() == pytest.approx(0.4, rel=1e-12)
    rim = np.abs(V[:, 2]) < 1e-9
    rho = np.hypot(V[rim, 0], V[rim, 1])
    assert rho.max() <= 1.1 + 1e-12 and rho.min() >= 0.9 - 1e-12
    assert np.ptp(rho) > 0.1


def test_bumpy_sphere_volume_decreases_monotonically_under_the_flow():
    quality = MeshQuality()
    traj = simulate(*bumpy_sphere(), 0.0025, 32, save_every=0, observer=quality)
    assert traj.status == "ok"
    volume = quality.frame()["volume"].to_numpy()
    assert len(volume) == 33
    assert (np.diff(volume) < 0).all()
    # enclosed volume of MCF decreases at rate -(surface area) * <H> ~ 4 pi H
    assert volume[-1] < 0.8 * volume[0]


@pytest.mark.parametrize("radius, half_height, waist",
                         [(1.0, 0.5, 0.8483379), (2.0, 1.0, 1.6966759)])
def test_catenoid_waist_solves_the_boundary_condition(radius, half_height, waist):
    a = catenoid_waist(radius, half_height)
    assert a == pytest.approx(waist, rel=1e-6)
    assert a * np.cosh(half_height / a) == pytest.approx(radius, rel=1e-12)


def test_catenoid_waist_beyond_the_critical_ratio_raises():
    with pytest.raises(ValueError, match="no catenoid"):
        catenoid_waist(1.0, 0.7)


def test_unknown_shape_is_named():
    with pytest.raises(ValueError, match="unknown shape 'torus'"):
        make_shape("torus")
