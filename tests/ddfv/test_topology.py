import numpy as np
import pytest
from conftest import flat_lattice

from ddfv.topology import diamond_mesh, locality_order
from mcfbench.geometry.spheres import icosphere


@pytest.mark.parametrize("level", [0, 1, 2, 3])
def test_icosphere_diamond_counts(level):
    V, F = icosphere(level)
    mesh = diamond_mesh(F, len(V))
    assert (mesh.n_f, mesh.n_t) == (10 * 4**level + 2, 20 * 4**level)
    assert len(mesh.diamonds) == 3 * mesh.n_t // 2          # n_dia = 3/2 n_T
    assert mesh.n_f - len(mesh.diamonds) + mesh.n_t == 2     # Euler characteristic
    assert not mesh.has_boundary


def test_diamonds_and_halfedges_are_consistent():
    V, F = icosphere(2)
    mesh = diamond_mesh(F)
    a, b, t1, t2 = mesh.diamonds.T
    halfedges = {(f[k], f[(k + 1) % 3]): t for t, f in enumerate(F) for k in range(3)}
    assert all(halfedges[(i, j)] == t for i, j, t in zip(a, b, t1))
    assert all(halfedges[(j, i)] == t for i, j, t in zip(a, b, t2))
    # the diamond of half-edge (t, k) is the edge faces[t, k] - faces[t, k+1]
    d = mesh.diamonds[mesh.halfedges]
    src, dst = F, F[:, [1, 2, 0]]
    assert np.all(((d[..., 0] == src) & (d[..., 1] == dst))
                  | ((d[..., 0] == dst) & (d[..., 1] == src)))


def test_boundary_of_open_lattice():
    m, k = 6, 5
    V, F = flat_lattice(m, k)
    mesh = diamond_mesh(F)
    assert mesh.boundary.sum() == 2 * (m + k)
    on_rim = (V[:, 0] % m == 0) | (V[:, 1] % k == 0)
    assert np.array_equal(mesh.boundary_vertices, on_rim)
    assert np.all(mesh.diamonds[mesh.boundary, 3] == -1)


def test_one_ring_of_icosahedron_vertex():
    V, F = icosphere(0)
    mesh = diamond_mesh(F)
    ring = mesh.one_ring(0)
    assert len(ring) == 5
    assert np.allclose(np.linalg.norm(V[ring] - V[0], axis=1),
                       np.linalg.norm(V[1] - V[0]))


def _tetrahedron():
    return np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_single_triangle_has_three_boundary_diamonds():
    mesh = diamond_mesh([[0, 1, 2]])
    assert (mesh.n_f, mesh.n_t, len(mesh.diamonds)) == (3, 1, 3)
    assert mesh.boundary.all() and mesh.boundary_vertices.all()
    assert sorted(map(tuple, mesh.diamonds[:, :3].tolist())) == [(0, 1, 0), (1, 2, 0), (2, 0, 0)]


def test_two_tetrahedra_give_two_closed_diamond_meshes():
    # validation (e.g. of non-manifold vertices) is the harness's, see test_mesh.py
    mesh = diamond_mesh(np.vstack([_tetrahedron(), _tetrahedron() + 4]))
    assert (mesh.n_f, mesh.n_t, len(mesh.diamonds)) == (8, 8, 12)
    assert not mesh.has_boundary


@pytest.mark.parametrize("faces, message", [
    (np.vstack([_tetrahedron(), [[0, 1, 4]]]),
     r"cannot build diamonds: edge \(1, 0\) has more than two triangles"),
    (np.vstack([_tetrahedron()[:3], [[1, 3, 2]]]),
     r"cannot build diamonds: triangles 0 and 3 both traverse edge 2 -> 1"),
    (_tetrahedron().astype(float), r"\(n_t, 3\) integer array, got shape \(4, 3\), dtype float64"),
    (_tetrahedron()[:, :2], r"\(n_t, 3\) integer array, got shape \(4, 2\)"),
])
def test_what_cannot_be_built_is_refused(faces, message):
    with pytest.raises(ValueError, match=message):
        diamond_mesh(faces)


def _bandwidth(faces):
    """Largest |i - j| over the edges (i, j) of a triangle list."""
    return int(np.abs(faces - np.roll(faces, 1, axis=1)).max())


def test_locality_order_is_a_renumbering_that_narrows_the_band():
    V, F = icosphere(4)
    vertex_order, face_order = locality_order(F, len(V))
    np.testing.assert_array_equal(np.sort(vertex_order), np.arange(len(V)))
    np.testing.assert_array_equal(np.sort(face_order), np.arange(len(F)))
    rank = np.empty_like(vertex_order)
    rank[vertex_order] = np.arange(len(V))
    renumbered = rank[F[face_order]]
    # the same surface: the triangles as vertex sets are unchanged
    assert {frozenset(f) for f in vertex_order[renumbered].tolist()} == \
        {frozenset(f) for f in F.tolist()}
    # the icosphere's numbering spans most of the mesh (1925 of 2562), RCM
    # about 1.6 sqrt(n) (81)
    assert _bandwidth(F) > 0.7 * len(V)
    assert _bandwidth(renumbered) < 2 * np.sqrt(len(V))
    # triangles sorted by their smallest new vertex number
    assert np.all(np.diff(renumbered.min(axis=1)) >= 0)


@pytest.mark.parametrize("parts", [1, 2, 3])
def test_diamond_blocks_never_share_a_vertex_across_threads(parts):
    V, F = icosphere(3)
    vertex_order, face_order = locality_order(F, len(V))
    rank = np.empty_like(vertex_order)
    rank[vertex_order] = np.arange(len(V))
    mesh = diamond_mesh(rank[F[face_order]], len(V))
    order, starts = mesh.diamond_blocks(parts)
    assert len(starts) == parts + 2
    np.testing.assert_array_equal(np.sort(order), np.arange(len(mesh.diamonds)))
    d = mesh.diamonds[order.astype(np.int64)]
    # block k < parts: all four vertices in part k (F-vertices and T-vertices
    # each cut into `parts` consecutive ranges); the last block: the rest
    part_f = np.arange(mesh.n_f) * parts // mesh.n_f
    part_t = np.arange(mesh.n_t) * parts // mesh.n_t
    parts_of = np.stack([part_f[d[:, 0]], part_f[d[:, 1]], part_t[d[:, 2]], part_t[d[:, 3]]])
    for k in range(parts):
        block = slice(int(starts[k]), int(starts[k + 1]))
        assert (parts_of[:, block] == k).all()
        assert np.all(np.diff(order[block].astype(np.int64)) > 0)   # in mesh order
    across = parts_of[:, int(starts[parts]):]
    assert (across.min(axis=0) != across.max(axis=0)).all()
    if parts == 1:
        np.testing.assert_array_equal(order, np.arange(len(mesh.diamonds)))
    else:   # the RCM ranges meet along a short front: few diamonds across
        assert 0 < starts[parts + 1] - starts[parts] < 0.15 * len(order)
