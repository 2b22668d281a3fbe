"""The harness's validation and summary of input surfaces (mcfbench.geometry.mesh)."""

import numpy as np
import pytest
from conftest import cylinder, flat_lattice

from mcfbench.geometry.mesh import MeshError, MeshSummary, summarize, validate_mesh


def icosahedron():
    g = (1.0 + np.sqrt(5.0)) / 2.0
    V = np.array([[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g],
                  [0, -1, -g], [0, 1, -g], [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]])
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
                  [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
                  [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
                  [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


def torus(m=8, k=6, R=2.0, r=0.7):
    u = 2 * np.pi * np.arange(m) / m
    v = 2 * np.pi * np.arange(k) / k
    uu, vv = np.meshgrid(u, v, indexing="xy")           # row j = v_j, column i = u_i
    V = np.column_stack([((R + r * np.cos(vv)) * np.cos(uu)).ravel(),
                         ((R + r * np.cos(vv)) * np.sin(uu)).ravel(),
                         (r * np.sin(vv)).ravel()])
    i, j = np.meshgrid(np.arange(m), np.arange(k), indexing="xy")
    p, q = (j * m + i).ravel(), (j * m + (i + 1) % m).ravel()
    s, t = (((j + 1) % k) * m + (i + 1) % m).ravel(), (((j + 1) % k) * m + i).ravel()
    return V, np.concatenate([np.column_stack([p, q, s]), np.column_stack([p, s, t])])


def tetrahedron(shift=0.0):
    V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float) + shift
    return V, np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def two_cones():
    """Two open cones (rings 1-4 above, 5-8 below) sharing the apex 0."""
    c, s = np.cos(np.pi / 2 * np.arange(4)), np.sin(np.pi / 2 * np.arange(4))
    V = np.vstack([[0, 0, 0], np.column_stack([c, s, np.ones(4)]),
                   np.column_stack([c, s, -np.ones(4)])])
    i = np.arange(4)
    F = np.vstack([np.column_stack([np.zeros(4, int), 1 + i, 1 + (i + 1) % 4]),
                   np.column_stack([np.zeros(4, int), 5 + (i + 1) % 4, 5 + i])])
    return V, F


def refused(V, F, message, **ids):
    with pytest.raises(MeshError, match=message) as info:
        validate_mesh(V, F, **ids)
    return str(info.value)


# --- refusals, each naming the elements -----------------------------------

def test_non_manifold_edge_is_named():
    V, F = tetrahedron()
    text = refused(np.vstack([V, [[0.5, -1, 0.5]]]), np.vstack([F, [[0, 1, 4]]]),
                   "non-manifold edge")
    assert text == ("non-manifold edge(s): 1 edge(s) have more than two triangles: "
                    "edge (0, 1) is shared by triangles [0, 1, 4]")


def test_non_manifold_vertex_of_two_cones_is_named():
    V, F = two_cones()
    text = refused(V, F, r"non-manifold vertex\(es\) \[0\]")
    assert text.endswith("as where two surfaces touch at a point (vertex 0 has 2 fans)")


def test_two_closed_surfaces_sharing_a_vertex_are_refused():
    (V1, F1), (V2, F2) = tetrahedron(), tetrahedron(shift=-1.0)
    F2 = np.where(F2 == 3, -4, F2) + 4          # its vertex 3 becomes vertex 0 of the first
    V = np.vstack([V1, V2[:3]])
    refused(V, np.vstack([F1, F2]), r"^non-manifold vertex\(es\) \[0\]: .* \(vertex 0 has 2 fans\)$")


def test_inconsistent_orientation_names_triangles_and_edges():
    V, F = icosahedron()
    F = F.copy()
    F[0] = F[0, ::-1]                                       # (5, 11, 0)
    text = refused(V, F, "inconsistent orientation at 3 edge")
    assert "triangles 0 and 4 both traverse edge 11 -> 0" in text


def test_duplicate_faces_are_named():
    V, F = tetrahedron()
    text = refused(V, np.vstack([F, [[2, 1, 0]]]), "duplicate triangles")
    assert text.endswith("1 triangle(s) repeat an earlier one, pairs (0, 4)")


def test_zero_area_triangle_is_named():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0.5, 0.5, 0]])   # 3 on the diagonal 0-2
    text = refused(V, [[0, 1, 2], [0, 2, 3]], r"zero-area \(degenerate\) triangle\(s\) \[1\]")
    assert text.endswith("e.g. triangle 1 = (0, 2, 3)")


def test_nan_coordinate_is_named():
    V, F = icosahedron()
    V[3] = [np.nan, 0, 0]
    refused(V, F, r"^NaN or inf coordinates at vertex\(es\) \[3\]$")
    V[7, 2] = np.inf
    refused(V, F, r"vertex\(es\) \[3, 7\]")


def test_messages_use_the_given_numbers():
    V, F = icosahedron()
    V[3] = np.nan
    refused(V, F, r"vertex\(es\) \[103\]", vertex_ids=np.arange(12) + 100)
    V, F = tetrahedron()
    refused(V, np.vstack([F, [[1, 1, 2]]]), r"triangle\(s\) \[9\] repeat a vertex, e.g. "
            r"triangle 9 = \(11, 11, 12\)", vertex_ids=np.arange(4) + 10, face_ids=[5, 6, 7, 8, 9])


def test_unreferenced_vertex_is_named():
    V, F = tetrahedron()
    refused(np.vstack([V, [[5, 5, 5]]]), F, r"unreferenced vertex\(es\) \[4\]: no triangle uses")


def test_indices_out_of_range_are_named():
    V, F = tetrahedron()
    F = F.copy()
    F[3, 1] = 7
    refused(V, F, r"face indices out of range: triangle\(s\) \[3\] refer to vertex index\(es\) "
            r"\[7\], but there are 4 vertices \(valid indices 0 to 3\)")
    refused(V, -F, r"triangle\(s\) \[0, 1, 2, 3\] refer to vertex index\(es\) \[-7, -3, -2, -1\]")


def test_triangle_repeating_a_vertex_is_named():
    V, F = tetrahedron()
    refused(V, np.vstack([F, [[1, 2, 1]]]),
            r"^triangle\(s\) \[4\] repeat a vertex, e.g. triangle 4 = \(1, 2, 1\)$")


@pytest.mark.parametrize("V, F, message", [
    (np.zeros((4, 2)), tetrahedron()[1], r"vertices must have shape \(n, 3\), got shape \(4, 2\)"),
    (tetrahedron()[0], tetrahedron()[1][:, :2], r"faces must have shape \(m, 3\)"),
    (tetrahedron()[0], tetrahedron()[1].astype(float), "integer vertex indices, got dtype float64"),
    (tetrahedron()[0].astype(str), tetrahedron()[1], "vertices must be real numbers"),
    (tetrahedron()[0], np.zeros((0, 3), int), "the surface has no triangles"),
])
def test_bad_shapes_and_dtypes(V, F, message):
    refused(V, F, message)


def test_huge_coordinates_are_fine_and_a_degenerate_triangle_at_that_scale_is_not():
    V, F = icosahedron()
    big = summarize(1e200 * V, F)
    assert big.smallest_angle == pytest.approx(60.0)
    assert big.area_ratio == pytest.approx(1.0)
    assert big.mean_edge == pytest.approx(1.0515e200, rel=1e-4)
    assert summarize(1e-200 * V, F).mean_edge == pytest.approx(1.0515e-200, rel=1e-4)

    thin = np.array([[0, 0, 0], [1, 0, 0], [2, 1e-3, 0]]) * 1e200
    validate_mesh(thin, [[0, 1, 2]])                        # area / l^2 = 1.25e-4
    thin[2, 1] = 1e186                                      # area / l^2 = 1.25e-15
    refused(thin, [[0, 1, 2]], r"zero-area \(degenerate\) triangle\(s\) \[0\]")


def test_coordinates_that_overflow_or_underflow_are_refused():
    V, F = tetrahedron()
    refused(np.where(V == 1, 1e308, -1e308), F,
            r"coordinates overflow: the extent of the mesh along x \(max - min\) is not a "
            r"finite double \(coordinates up to 1e\+308\)")
    refused(V * 1.5e308, F, "coordinates overflow: the diagonal of the bounding box")
    refused(V * 1e-310, F, "coordinates too small: the largest extent of the mesh, 1e-310")


def test_returns_float64_and_int64():
    V, F = validate_mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.array([[0, 1, 2]], np.int32))
    assert V.dtype == np.float64 and F.dtype == np.int64 and F.tolist() == [[0, 1, 2]]


# --- summaries of known meshes --------------------------------------------

def test_icosahedron_summary():
    s = summarize(*icosahedron())
    assert (s.vertices, s.faces, s.edges, s.components) == (12, 20, 30, 1)
    assert (s.euler_characteristic, s.genus, s.boundary_loops) == (2, (0,), 0)
    assert s.closed
    assert s.smallest_angle == pytest.approx(60.0)
    assert s.area_ratio == pytest.approx(1.0)
    assert s.mean_edge == pytest.approx(4 / np.sqrt(10 + 2 * np.sqrt(5)))
    assert str(s) == ("12 vertices, 20 faces, 1 component, genus 0, 0 boundary loops, "
                      "smallest angle 60.0 deg, area ratio 1.00, mean edge 1.0515")


def test_torus_has_genus_one():
    s = summarize(*torus(8, 6))
    assert (s.vertices, s.faces, s.edges) == (48, 96, 144)
    assert (s.euler_characteristic, s.genus, s.boundary_loops) == (0, (1,), 0)


def test_open_grid_has_one_boundary_loop():
    s = summarize(*flat_lattice(6, 5))
    assert (s.vertices, s.faces, s.edges, s.euler_characteristic) == (42, 60, 101, 1)
    assert (s.components, s.genus, s.boundary_loops) == (1, (0,), 1)
    assert s.smallest_angle == pytest.approx(45.0)
    assert s.mean_edge == pytest.approx((71 + 30 * np.sqrt(2)) / 101)
    assert str(s).startswith("42 vertices, 60 faces, 1 component, genus 0, 1 boundary loop, "
                             "smallest angle 45.0 deg, area ratio 1.00")


def test_open_cylinder_has_two_boundary_loops_and_genus_zero():
    s = summarize(*cylinder(24, 8))
    assert (s.euler_characteristic, s.genus, s.boundary_loops) == (0, (0,), 2)


def test_two_disjoint_tetrahedra_are_two_components():
    (V1, F1), (V2, F2) = tetrahedron(), tetrahedron(shift=5.0)
    s = summarize(np.vstack([V1, V2]), np.vstack([F1, F2 + 4]))
    assert (s.components, s.genus, s.euler_characteristic, s.boundary_loops) == (2, (0, 0), 4, 0)
    assert s.area_ratio == pytest.approx(np.sqrt(3))      # slanted face / right-angled faces
    assert "8 vertices, 8 faces, 2 components, genus [0, 0], 0 boundary loops" in str(s)


def test_single_triangle_is_a_valid_open_surface():
    s = summarize([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    assert isinstance(s, MeshSummary)
    assert (s.vertices, s.faces, s.edges, s.genus, s.boundary_loops) == (3, 1, 3, (0,), 1)
    assert s.smallest_angle == pytest.approx(45.0)
    assert "\n" not in str(s) and "3 vertices, 1 face, 1 component" in str(s)


def test_summarize_refuses_invalid_input():
    with pytest.raises(ValueError, match="non-manifold vertex"):
        summarize(*two_cones())
