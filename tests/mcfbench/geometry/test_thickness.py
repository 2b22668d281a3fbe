"""The thin-feature criterion (mcfbench.geometry.thickness): exact distances
across a box, a thin torus thin and a fat one and a sphere not, the same
verdict whatever the file's orientation, no thickness on a flat open patch,
and the committed meshes' verdicts as the problem meshes' README states them
(fins on blub and blub_filled, none on the smooth closed shapes)."""

import numpy as np
import pytest

from mcfbench.geometry.committed_meshes import read_committed_mesh
from mcfbench.geometry.shapes import flat_patch, torus
from mcfbench.geometry.spheres import icosphere
from mcfbench.geometry.thickness import THIN_SHARE, thin_features, triangle_thickness


def box(a, b, c):
    """The box [0, a] x [0, b] x [0, c] as 12 outward triangles."""
    V = np.array([[x, y, z] for x in (0, a) for y in (0, b) for z in (0, c)], float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    F = np.array([t for q in quads for t in ((q[0], q[1], q[2]), (q[0], q[2], q[3]))])
    return V, F


def test_the_distance_across_a_box_is_its_extent_along_each_normal():
    V, F = box(1.0, 2.0, 3.0)
    P = V[F]
    normal = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    extent = np.abs(normal / np.linalg.norm(normal, axis=1)[:, None]) @ np.array([1.0, 2.0, 3.0])
    np.testing.assert_allclose(triangle_thickness(V, F), extent, rtol=1e-6, atol=0)
    # an inward-oriented file is measured from its inside all the same (libigl
    # casts in single precision: 1e-6)
    np.testing.assert_allclose(triangle_thickness(V, F[:, ::-1]), extent, rtol=1e-6, atol=0)


def test_a_thin_torus_is_thin_a_fat_torus_and_a_sphere_are_not():
    thin = thin_features(*torus(R=2.0, r=0.05, n_major=64, n_minor=8))
    fat = thin_features(*torus(R=2.0, r=0.5, n_major=32, n_minor=8))
    sphere = thin_features(*icosphere(3))
    # the thin tube's diameter 0.1 is below 2 h (h about 0.1): every triangle
    assert thin.thin_share == pytest.approx(1.0) and thin.thin
    # the fat tube's diameter 1 is above 2 h = 0.51 on every ray; the sphere's 2 too
    assert fat.thin_share == 0.0 and not fat.thin
    assert sphere.thin_share == 0.0 and not sphere.thin
    assert 2 * 0.5 > 2 * fat.mean_edge and 2 * 0.05 < 2 * thin.mean_edge


def test_the_verdict_is_the_share_of_area_against_the_stated_threshold():
    # a fat torus with one thin part: a band of the tube squeezed to radius 0.02
    V, F = torus(R=2.0, r=0.5, n_major=64, n_minor=8)
    angle = np.arctan2(V[:, 1], V[:, 0])
    centre = np.c_[2 * np.cos(angle), 2 * np.sin(angle), 0 * angle]
    squeeze = np.where(np.abs(angle) < 0.2, 0.04, 1.0)[:, None]
    result = thin_features(centre + squeeze * (V - centre), F)
    assert 0 < result.thin_share < 0.5
    assert result.thin == (result.thin_share > THIN_SHARE)


def test_an_open_flat_patch_has_no_thickness():
    V, F = flat_patch(level=1)
    assert np.isinf(triangle_thickness(V, F)).all()
    assert thin_features(V, F).thin_share == 0.0


@pytest.mark.parametrize("name, thin", [("blub", True), ("blub_filled", True), ("spot", False),
                                        ("torus", False), ("ball", False)])
def test_committed_meshes_with_fins_are_thin_the_smooth_ones_not(name, thin):
    result = thin_features(*read_committed_mesh(name))
    assert result.thin is thin
    assert (result.thin_share > 0.04) if thin else (result.thin_share < 0.005)
