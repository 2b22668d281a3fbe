"""Problem metrics and mesh-quality monitors (mcfbench/geometry/metrics.py)."""

import numpy as np
import pytest

from baselines.cotan import CotanFlow
from ddfv import Flow
from mcfbench.geometry.metrics import (
    area,
    area_ratio,
    aspect_ratios,
    catenoid_parameter,
    catenoid_profile_error,
    covolume_ratio,
    flipped_triangles,
    l2_height,
    lumped_mass,
    max_aspect_ratio,
    max_height,
    max_speed,
    mean_edge_length,
    min_angle,
    quality,
    triangle_angles,
    triangle_areas,
    volume,
)
from mcfbench.geometry.shapes import cylinder, flat_lattice, hemisphere
from mcfbench.geometry.spheres import icosahedron, icosphere

# a* of R = 1, h = 0.5 to 21 digits (mpmath.findroot at 30 digits)
A_CATENOID = 0.848337938094979002054


def unit_cube():
    """The cube [0, 1]^3 as 12 triangles with outward normals."""
    V = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5],   # x = 0, x = 1
                  [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],   # y = 0, y = 1
                  [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])  # z = 0, z = 1
    return V, F


EQUILATERAL = (np.array([[0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]]), np.array([[0, 1, 2]]))
RIGHT_ISOSCELES = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float), np.array([[0, 1, 2]]))


# ---------------------------------------------------------- measures

def test_unit_cube_volume_and_area():
    V, F = unit_cube()
    assert volume(V, F) == pytest.approx(1.0, abs=1e-15)
    assert area(V, F) == pytest.approx(6.0, abs=1e-15)
    assert volume(V + [3.0, -2.0, 5.0], F) == pytest.approx(1.0, rel=1e-14)  # any origin
    assert volume(V, F[:, ::-1]) == pytest.approx(-1.0, abs=1e-15)         # inward: negative


def test_icosphere_volume_is_below_the_ball():
    V, F = icosahedron()
    # regular icosahedron of circumradius 1: edge a = 4 / sqrt(10 + 2 sqrt 5)
    a = 4 / np.sqrt(10 + 2 * np.sqrt(5))
    assert volume(V, F) == pytest.approx(5 / 12 * (3 + np.sqrt(5)) * a**3, rel=1e-14)
    assert area(V, F) == pytest.approx(5 * np.sqrt(3) * a**2, rel=1e-14)


def test_lumped_mass_gives_a_third_of_each_triangle():
    V, F = RIGHT_ISOSCELES
    np.testing.assert_allclose(lumped_mass(V, F), [1 / 6] * 3, rtol=1e-15)
    V, F = unit_cube()
    assert lumped_mass(V, F).sum() == pytest.approx(6.0, rel=1e-15)


def test_mean_edge_length_counts_each_edge_once():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    F = np.array([[0, 1, 2], [0, 2, 3]])
    assert mean_edge_length(V, F) == pytest.approx((4 + np.sqrt(2)) / 5, rel=1e-15)


def test_mean_edge_length_is_that_of_the_sorted_unique_edges_bit_for_bit():
    # the records' h: the same number as the mean over np.unique's rows (the
    # edges in the same order), on an irregular mesh whose indices are shuffled
    from mcfbench.geometry.spheres import icosphere

    V, F = icosphere(3)
    V = V * (1.0 + 0.1 * np.sin(7 * V[:, :1]))
    perm = np.random.default_rng(3).permutation(len(V))
    V, F = V[np.argsort(perm)], perm[F]
    edges = np.unique(np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1), axis=0)
    assert len(edges) == 3 * len(F) // 2
    assert mean_edge_length(V, F) == np.linalg.norm(V[edges[:, 1]] - V[edges[:, 0]],
                                                    axis=1).mean()


# ------------------------------------------------------ height metrics

def test_height_of_a_raised_square_and_a_tilted_triangle():
    V = np.array([[0, 0, 0.3], [1, 0, 0.3], [1, 1, 0.3], [0, 1, 0.3]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    assert max_height(V) == 0.3
    assert l2_height(V, F) == pytest.approx(0.3, rel=1e-15)  # sqrt(area * 0.3^2), area 1
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, -1.0]])
    # area sqrt(2)/2, masses sqrt(2)/6, heights 0, 0, -1
    assert max_height(V) == 1.0
    assert l2_height(V, [[0, 1, 2]]) == pytest.approx(np.sqrt(np.sqrt(2) / 6), rel=1e-15)


def test_height_of_the_hemisphere_and_the_disk():
    V, F = hemisphere(10)
    assert max_height(V) == 1.0
    # sqrt(int z^2 dA) over the unit hemisphere = sqrt(2 pi / 3); lumped mesh within 1 %
    assert l2_height(V, F) == pytest.approx(np.sqrt(2 * np.pi / 3), rel=0.01)
    V[:, 2] = 0.0
    assert max_height(V) == 0.0 and l2_height(V, F) == 0.0


# ------------------------------------------------------------ catenoid

def test_catenoid_parameter_solves_the_boundary_condition():
    a = catenoid_parameter(1.0, 0.5)
    assert a == pytest.approx(A_CATENOID, rel=2e-16)
    assert a * np.cosh(0.5 / a) == pytest.approx(1.0, rel=2e-16)
    # NOTES.md's 0.8483379380948415 agrees to 12 digits (its 13th is off)
    assert a == pytest.approx(0.8483379380948415, rel=2e-13)
    assert catenoid_parameter(2.0, 1.0) == pytest.approx(2 * A_CATENOID, rel=4e-16)
    assert catenoid_parameter(1.0, 0.55) == pytest.approx(0.80457782, rel=1e-8)


def test_catenoid_parameter_beyond_the_critical_ratio_raises():
    with pytest.raises(ValueError, match="no catenoid"):
        catenoid_parameter(1.0, 0.7)


def catenoid_mesh(around=48, along=16, factor=1.0):
    """The cylinder's vertices moved radially onto factor * a cosh(z/a)."""
    V, F = cylinder(around, along)
    rho = factor * A_CATENOID * np.cosh(V[:, 2] / A_CATENOID)
    return np.column_stack([V[:, :2] * rho[:, None], V[:, 2]]), F


def test_exact_catenoid_has_no_error():
    V, _ = catenoid_mesh()
    err = catenoid_profile_error(V, A_CATENOID)
    assert err["neck_radius"] == pytest.approx(A_CATENOID, rel=1e-15)
    assert abs(err["neck_error"]) < 1e-15 and err["max_radial_error"] < 1e-15


def test_catenoid_without_a_ring_on_the_neck_plane():
    V, _ = catenoid_mesh(24, 7)  # rings at z = +-1/14: the neck is measured through cosh
    err = catenoid_profile_error(V, A_CATENOID)
    assert abs(err["neck_error"]) < 1e-15 and err["max_radial_error"] < 1e-15


def test_shrunk_catenoid_has_the_known_relative_error():
    V, _ = catenoid_mesh(factor=0.98)
    err = catenoid_profile_error(V, A_CATENOID)
    assert err["neck_radius"] == pytest.approx(0.98 * A_CATENOID, rel=1e-14)
    assert err["neck_error"] == pytest.approx(-0.02, rel=1e-12)      # signed: thinner
    assert err["max_radial_error"] == pytest.approx(0.02, rel=1e-12)


def test_the_initial_cylinder_is_off_by_one_over_a_minus_one():
    V, _ = cylinder(24, 8)
    err = catenoid_profile_error(V, A_CATENOID)
    assert err["neck_error"] == pytest.approx(1 / A_CATENOID - 1, rel=1e-14)  # 0.17878...
    assert err["max_radial_error"] == pytest.approx(1 / A_CATENOID - 1, rel=1e-14)


def test_fixed_vertices_are_left_out():
    V, _ = catenoid_mesh(24, 8)
    boundary = np.abs(V[:, 2]) == 0.5
    V[boundary, :2] *= 1.5  # wrong, but fixed
    assert catenoid_profile_error(V, A_CATENOID)["max_radial_error"] == pytest.approx(0.5)
    for mask in (boundary, np.flatnonzero(boundary)):
        assert catenoid_profile_error(V, A_CATENOID, mask)["max_radial_error"] < 1e-15


# -------------------------------------------------------- mesh quality

def test_equilateral_triangle():
    V, F = EQUILATERAL
    np.testing.assert_allclose(triangle_angles(V, F), [[60, 60, 60]], rtol=1e-14)
    assert min_angle(V, F) == pytest.approx(60.0, rel=1e-14)
    assert max_aspect_ratio(V, F) == pytest.approx(1.0, rel=1e-14)
    assert area_ratio(V, F) == 1.0


def test_right_isosceles_triangle():
    V, F = RIGHT_ISOSCELES
    np.testing.assert_allclose(triangle_angles(V, F), [[90, 45, 45]], rtol=1e-14)
    assert min_angle(V, F) == pytest.approx(45.0, rel=1e-14)
    # R = sqrt(2)/2, r = (2 - sqrt 2)/2: R / (2r) = (1 + sqrt 2) / 2
    assert max_aspect_ratio(V, F) == pytest.approx((1 + np.sqrt(2)) / 2, rel=1e-14)
    assert triangle_areas(V, F)[0] == 0.5


def test_degenerate_and_unequal_triangles():
    V = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 2], [2, 0, 2]], float)
    assert aspect_ratios(V, [[0, 1, 2]])[0] == np.inf
    assert area_ratio(V, [[0, 1, 3], [0, 2, 4]]) == pytest.approx(4.0)  # areas 1/2 and 2
    assert area_ratio(V, [[0, 1, 3], [0, 1, 2]]) == np.inf


def test_quality_of_the_icosahedron():
    q = quality(*icosahedron())
    assert q["min_angle"] == pytest.approx(60.0, rel=1e-13)
    assert q["max_aspect_ratio"] == pytest.approx(1.0, rel=1e-13)
    assert q["area_ratio"] == pytest.approx(1.0, rel=1e-13)
    assert q["flipped_triangles"] == 0


def test_a_reversed_triangle_is_counted_once():
    V, F = flat_lattice(6, 5)
    assert flipped_triangles(V, F) == 0
    F = F.copy()
    F[17] = F[17, ::-1]
    assert flipped_triangles(V, F) == 1


def test_a_folded_triangle_is_counted_once():
    V, F = flat_lattice(6, 5)
    normals0 = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    V = V.copy()
    # vertex (3, 2) pushed across the edge (4, 2)-(4, 3) of exactly one of its six triangles
    V[2 * 7 + 3, :2] = [4.2, 2.5]
    assert flipped_triangles(V, F) == 1
    assert flipped_triangles(V, F, reference_normals=normals0) == 1
    assert flipped_triangles(V, F[:, ::-1]) == 1  # orientation-independent without reference
    assert flipped_triangles(V, F[:, ::-1], reference_normals=normals0) == len(F) - 1


def test_reference_normals_must_match_the_triangles():
    V, F = flat_lattice(2, 2)
    with pytest.raises(ValueError, match="one per triangle"):
        flipped_triangles(V, F, reference_normals=np.zeros((3, 3)))


# -------------------------------------------------------- steady state

def test_max_speed_is_the_largest_displacement_over_tau():
    V0, _ = icosahedron()
    V1 = V0.copy()
    V1[4] += [0.003, 0.004, 0.0]
    V1[7] += [0.001, 0.0, 0.0]
    assert max_speed(V0, V1, 0.001) == pytest.approx(5.0, rel=1e-12)
    assert max_speed(V0, V0, 0.1) == 0.0
    with pytest.raises(ValueError, match="same shape"):
        max_speed(V0, V1[:5], 0.1)
    with pytest.raises(ValueError, match="tau must be positive"):
        max_speed(V0, V1, 0.0)


@pytest.mark.parametrize("layout", ["C", "F"])
def test_max_speed_is_the_largest_norm_bitwise(layout):
    """The compiled pass gives numpy's largest row norm over tau to the last bit, for the
    vertex schemes' (n, 3) views of (3, n) arrays too; a NaN coordinate gives NaN."""
    rng = np.random.default_rng(3)
    P, V = (np.asarray(rng.standard_normal((40, 3)), order=layout) for _ in range(2))
    expected = np.linalg.norm(V - P, axis=1).max() / 0.003
    assert max_speed(P, V, 0.003) == expected
    V[17, 1] = np.nan
    assert np.isnan(max_speed(P, V, 0.003))


def test_inputs_of_the_wrong_shape_are_refused():
    V, F = icosahedron()
    with pytest.raises(ValueError, match=r"vertices must have shape \(n, 3\)"):
        area(V.T, F)
    with pytest.raises(ValueError, match="faces must be an"):
        area(V, F.astype(float))
    with pytest.raises(ValueError, match="face indices"):
        volume(V[:5], F)


def _numpy_quality(V, F):
    """The monitors of :func:`quality` evaluated with plain numpy (the test oracle)."""
    from mcfbench.geometry.metrics import (
        aspect_ratios,
        flipped_triangles,
        triangle_areas,
    )

    A = triangle_areas(V, F)
    return {"min_angle": float(triangle_angles(V, F).min()),
            "max_aspect_ratio": float(aspect_ratios(V, F).max()),
            "area_ratio": float(A.max() / A.min()),
            "flipped_triangles": flipped_triangles(V, F)}


def test_quality_kernel_matches_a_numpy_evaluation():
    from mcfbench.geometry.metrics import edge_neighbours
    from mcfbench.geometry.spheres import icosphere

    rng = np.random.default_rng(3)
    V, F = icosphere(3)
    neighbours = edge_neighbours(F)
    for noise in (0.0, 0.002, 0.05):
        W = V + noise * rng.standard_normal(V.shape)
        expected = _numpy_quality(W, F)
        for got in (quality(W, F, neighbours), quality(W, F)):
            assert got["flipped_triangles"] == expected["flipped_triangles"]
            for key in ("min_angle", "max_aspect_ratio", "area_ratio"):
                assert got[key] == pytest.approx(expected[key], rel=1e-12), key
    with pytest.raises(ValueError):
        quality(V, F, (np.array([0]), np.array([len(F)])))


def test_covolume_ratio_of_known_covolumes_and_of_a_flowing_mesh():
    """The largest ratio over the edges, either way round; 1 on the icosahedron (equal
    covolumes by symmetry), for the lumped mass of cotan and DDFV's chi alike; a
    non-positive covolume is a collapsed cell (inf), a non-finite one NaN."""
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    assert covolume_ratio([1.0, 2.0, 8.0, 0.5], faces) == 16.0        # edge 2-3
    assert covolume_ratio([3.0, 3.0, 3.0, 3.0], faces) == 1.0
    assert covolume_ratio([1.0, 0.0, 1.0, 1.0], faces) == np.inf
    assert np.isnan(covolume_ratio([1.0, np.nan, 1.0, 1.0], faces))
    with pytest.raises(ValueError, match="one per vertex"):
        covolume_ratio([1.0, 2.0], faces)
    V, F = icosphere(0)
    for flow in (CotanFlow(V, F, 0.01), Flow(V, F, 0.01)):
        assert covolume_ratio(flow.l2_weights[:len(V)], F) == pytest.approx(1.0, abs=1e-12)
    # level 2 of the icosphere is graded: its covolumes differ by up to ~1.3
    V, F = icosphere(2)
    ratio = covolume_ratio(CotanFlow(V, F, 0.01).l2_weights, F)
    masses = CotanFlow(V, F, 0.01).l2_weights
    i, j = F.ravel(), F[:, [1, 2, 0]].ravel()
    assert ratio == pytest.approx(max((masses[i] / masses[j]).max(),
                                      (masses[j] / masses[i]).max()))
    assert 1.1 < ratio < 1.5
