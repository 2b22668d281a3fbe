"""Loop subdivision to the limit surface (mcfbench.geometry.subdivision): counts,
closed oriented output, the limit mask's eigenvector property, affine and
relabelling invariance, flat regions stay flat, and the levels converge to one
surface (distance between successive levels ~4x smaller per level)."""

import igl
import numpy as np
import pytest

from mcfbench.geometry.mesh import summarize, validate_mesh
from mcfbench.geometry.metrics import area, volume
from mcfbench.geometry.subdivision import (
    loop_beta,
    loop_limit,
    loop_limit_level,
    loop_limit_weight,
    loop_step,
)
from mcfbench.geometry.surfaces import make_surface


@pytest.fixture(scope="module")
def bumpy():
    """A small closed genus-1 mesh with irregular valences and positions."""
    V, F = make_surface("torus", R=2.0, r=0.7, n_major=12, n_minor=6)
    rng = np.random.default_rng(3)
    return V + 0.05 * rng.standard_normal(V.shape), F


def _edge_count(F):
    return len(np.unique(np.sort(np.r_[F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]], axis=1), axis=0))


def test_weights_match_loop_and_the_regular_limit_mask():
    assert loop_beta(np.array([6]))[0] == pytest.approx(1.0 / 16.0)
    assert loop_beta(np.array([3]))[0] == pytest.approx(3.0 / 16.0)
    assert loop_limit_weight(np.array([6]))[0] == pytest.approx(1.0 / 12.0)   # 1/2 and 6 x 1/12
    n = np.arange(3, 12)
    chi = loop_limit_weight(n)
    assert np.all((chi > 0) & (n * chi < 1))


def test_step_counts_and_output_is_a_closed_oriented_surface(bumpy):
    V, F = bumpy
    V2, F2 = loop_step(V, F)
    assert len(V2) == len(V) + _edge_count(F) and len(F2) == 4 * len(F)
    s = summarize(*validate_mesh(V2, F2))
    assert s.closed and s.components == 1 and s.genus == (1,)
    V3, F3 = loop_limit_level(V, F, 2)
    assert (len(V3), len(F3)) == (len(V2) + _edge_count(F2), 16 * len(F))
    sphere = make_surface("sphere", level=2, radius=1.0)
    assert volume(*loop_limit_level(*sphere, 1)) > 0     # orientation kept


def test_limit_position_is_unchanged_by_a_subdivision_step(bumpy):
    """The limit mask is the left eigenvector of eigenvalue 1 of the step: the
    limit of an old vertex is the same before and after subdividing."""
    V, F = bumpy
    V2, F2 = loop_step(V, F)
    assert np.abs(loop_limit(V2, F2)[: len(V)] - loop_limit(V, F)).max() < 1e-13


def test_libigl_loop_uses_other_vertex_weights():
    """Why igl.loop is not used: its old-vertex rule is Warren's 3/(8n), not
    Loop's beta_n (equal only for n = 3 and 6), so its steps do not continue
    to the limit the mask gives."""
    V, F = make_surface("sphere", level=0, radius=1.0)    # icosahedron, valence 5
    mine, _ = loop_step(V, F)
    theirs, _ = igl.loop(V, F)
    assert np.abs(mine[:12] - theirs[:12]).max() > 1e-3
    assert np.allclose(np.sort(mine[12:], axis=0), np.sort(theirs[12:], axis=0))


def test_subdivision_commutes_with_an_affine_map(bumpy):
    V, F = bumpy
    A = np.array([[1.2, 0.3, -0.1], [0.0, 0.8, 0.5], [0.4, 0.0, 1.1]])
    b = np.array([0.3, -2.0, 5.0])
    W, G = loop_limit_level(V @ A.T + b, F, 2)
    U, F2 = loop_limit_level(V, F, 2)
    assert np.array_equal(G, F2)
    assert np.abs(W - (U @ A.T + b)).max() < 1e-12


def test_flat_region_stays_flat():
    """The bottom of a sphere pressed onto z = 0: vertices far from the rim
    keep z = 0 exactly at every level (the masks are affine combinations of
    coplanar points)."""
    V, F = make_surface("sphere", level=3, radius=1.0)
    V = V.copy()
    V[:, 2] = np.maximum(V[:, 2], 0.0)
    for level in (0, 1, 2):
        U, _ = loop_limit_level(V, F, level)
        inner = (np.hypot(U[:, 0], U[:, 1]) < 0.5) & (U[:, 2] < 0.5)   # the bottom
        assert inner.sum() > 10 and np.abs(U[inner, 2]).max() < 1e-15


def test_relabelling_vertices_and_faces_gives_the_same_surface(bumpy):
    V, F = bumpy
    rng = np.random.default_rng(0)
    p = rng.permutation(len(V))
    inverse = np.argsort(p)
    G = inverse[F][rng.permutation(len(F))]
    G = np.roll(G, 1, axis=1)                      # rotated corners, same orientation
    U, F2 = loop_limit_level(V, F, 2)
    W, G2 = loop_limit_level(V[p], G, 2)
    assert np.allclose(np.sort(U.view("f8,f8,f8"), axis=0).view(float),
                       np.sort(W.view("f8,f8,f8"), axis=0).view(float), atol=1e-13)
    assert area(W, G2) == pytest.approx(area(U, F2), rel=1e-13)
    assert volume(W, G2) == pytest.approx(volume(U, F2), rel=1e-13)


def test_levels_converge_to_one_surface(bumpy):
    """Symmetric mean distance between the limit meshes of levels k and k+1
    (libigl's point-to-mesh distance): ~4x smaller per level (O(h^2))."""
    V, F = bumpy
    levels = [loop_limit_level(V, F, k) for k in range(4)]

    def distance(a, b):
        da = np.sqrt(igl.point_mesh_squared_distance(a[0], b[0], b[1])[0]).mean()
        db = np.sqrt(igl.point_mesh_squared_distance(b[0], a[0], a[1])[0]).mean()
        return 0.5 * (da + db)

    d = np.array([distance(levels[k], levels[k + 1]) for k in range(3)])
    ratios = d[:-1] / d[1:]
    assert np.all(ratios > 3.5) and np.all(ratios < 4.5), ratios
