"""The symmetric mean surface distance (mcfbench.geometry.surface_distance) on
exact cases: concentric spheres (-> |r1 - r2|, at second order in h), a surface
against itself (0), symmetry, invariance under rigid motions, two parallel
squares (their gap)."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from mcfbench.geometry.spheres import icosphere
from mcfbench.geometry.surface_distance import mean_surface_distance


SQUARE = (np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]),
          np.array([[0, 1, 2], [0, 2, 3]]))


def test_parallel_squares_are_their_gap_apart():
    V, F = SQUARE
    assert mean_surface_distance(V, F, V + [0, 0, 2.0], F[:, ::-1]) == pytest.approx(2.0,
                                                                                     rel=1e-15)
    # shifted along an edge by 1: half the vertices lie on the other square's
    # edge (distance 0), the other half at distance 1 from it, weighted by
    # their lumped areas (1/3 + 1/6 each way)
    assert mean_surface_distance(V, F, V + [1.0, 0, 0], F) == pytest.approx(0.5, rel=1e-15)


def test_concentric_spheres_tend_to_the_radii_difference_at_second_order():
    errors = [abs(mean_surface_distance(*icosphere(k, 1.0), *icosphere(k, 1.5)) - 0.5)
              for k in (1, 2, 3)]
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert errors[-1] < 1e-3 and np.all((1.9 < orders) & (orders < 2.1)), (errors, orders)
    inner_finer = mean_surface_distance(*icosphere(4, 0.5), *icosphere(2, 2.0))
    assert inner_finer == pytest.approx(1.5, rel=0.01)     # meshes need not match


def test_a_surface_against_itself_is_zero_and_the_distance_is_symmetric():
    A, B = icosphere(2), icosphere(3, 1.2)
    assert mean_surface_distance(*A, *A) == 0.0
    assert mean_surface_distance(*A, *B) == pytest.approx(mean_surface_distance(*B, *A),
                                                          rel=1e-14)
    assert mean_surface_distance(*A, *B) > 0.15        # and it does see them apart


def test_rigid_motions_of_both_surfaces_leave_it_unchanged():
    VA, FA = icosphere(2)
    VB, FB = icosphere(2, 1.3)
    VB = VB * [1.0, 0.8, 1.1] + [0.1, -0.2, 0.05]            # an ellipsoid off the centre
    before = mean_surface_distance(VA, FA, VB, FB)
    R, shift = Rotation.from_euler("xyz", [0.3, -1.1, 2.0]).as_matrix(), [3.0, -1.0, 0.5]
    after = mean_surface_distance(VA @ R.T + shift, FA, VB @ R.T + shift, FB)
    assert after == pytest.approx(before, rel=1e-12)


def test_bad_input_is_refused_by_name():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match="no triangle"):
        mean_surface_distance(V, F, V, np.zeros((0, 3), dtype=np.int64))
    with pytest.raises(ValueError, match="shape"):
        mean_surface_distance(V[:, :2], F, V, F)
    with pytest.raises(ValueError, match="face indices"):
        mean_surface_distance(V, F + len(V), V, F)
    with pytest.raises(ValueError, match="zero area"):
        mean_surface_distance(np.zeros_like(V), F, np.zeros_like(V), F)


def _distance_with_fresh_trees(VA, FA, VB, FB):
    """D(A, B) with libigl's one-call distance, which builds its tree every time."""
    import igl

    from mcfbench.geometry.metrics import lumped_mass

    def one_way(P, V, F):
        return np.sqrt(igl.point_mesh_squared_distance(P, V, F.astype(np.int64))[0])

    ma, mb = lumped_mass(VA, FA), lumped_mass(VB, FB)
    return float(ma @ one_way(VA, VB, FB) + mb @ one_way(VB, VA, FA)) / (ma.sum() + mb.sum())


def test_a_kept_surface_gives_the_numbers_of_fresh_trees_and_follows_its_content():
    from mcfbench.geometry import surface_distance

    reference = icosphere(3, 1.0)
    V, F = icosphere(2, 1.2)
    V[:, 0] *= 0.9
    first = mean_surface_distance(V, F, *reference)
    assert first == _distance_with_fresh_trees(V, F, *reference)     # bit for bit
    kept = len(surface_distance._kept)
    assert mean_surface_distance(V * 1.1, F, *reference) == \
        _distance_with_fresh_trees(V * 1.1, F, *reference)          # reference tree reused
    original = reference[0].copy()
    reference[0][:] *= 1.5                    # the same array, changed in place: a new surface
    assert mean_surface_distance(V, F, *reference) == \
        _distance_with_fresh_trees(V, F, *reference) != first
    # the first surface again, in another array: its kept entry holds its own copy of the
    # points, not the array changed since
    assert mean_surface_distance(V, F, original, reference[1]) == first
    assert kept <= len(surface_distance._kept) <= surface_distance.KEPT_SURFACES
