"""The surgery at a neck pinch (mcfbench/geometry/mesh_surgery.py; issue #45, item 1):
the dumbbell flowed by cotan to just before its pinch, cut and capped."""

import numpy as np
import pytest

from mcfbench.geometry import metrics
from mcfbench.geometry.collapse import component_topology
from mcfbench.geometry.measures import vertex_components
from mcfbench.geometry.mesh_surgery import (NECK_RESOLUTION, _oriented, cut_neck, find_neck,
                                            mean_curvature_vectors, pinched)
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.problems import get_problem
from mcfbench.running.schemes import SCHEMES


@pytest.fixture(scope="module")
def dumbbell():
    """Level 1 (2 546 vertices, h = 0.110) flowed by cotan, tau = 0.004, to t = 0.108
    (27 steps; the neck's radius 0.037 < h / 2; the run folds at t = 0.124)."""
    V, F = get_problem("dumbbell").mesh(1)
    traj = simulate(SCHEMES["cotan"].make(V, F, 0.004), 27, save_every=0)
    assert traj.ok, traj.message
    return traj.frames["vertices"][-1], F, metrics.mean_edge_length(V, F)


def test_the_sphere_has_no_neck_and_its_curvature_vector_points_in():
    V, F = icosphere(3)
    Hn = mean_curvature_vectors(2 * V, F)
    assert np.einsum("ij,ij->i", Hn, V).max() < 0
    assert np.linalg.norm(Hn, axis=1) == pytest.approx(1.0, rel=0.02)      # 2 / R, R = 2
    assert find_neck(2 * V, F) is None and not pinched(None, 1.0)


def test_the_dumbbell_neck_is_found_on_its_axis(dumbbell):
    V, F, h = dumbbell
    neck = find_neck(V, F)
    assert abs(neck.axis[2]) == pytest.approx(1.0, abs=1e-3)              # the z axis
    assert np.linalg.norm(neck.centre) < 5e-3
    assert 0.03 < neck.radius < 0.045 and len(neck.ring) == 16
    assert pinched(neck, h) and not pinched(neck, neck.radius / NECK_RESOLUTION * 0.99)
    V0, F0 = get_problem("dumbbell").mesh(1)
    assert not pinched(find_neck(V0, F0), h)                               # radius 0.3


def test_the_cut_leaves_two_closed_oriented_bulbs(dumbbell):
    V, F, h = dumbbell
    neck = find_neck(V, F)
    surgery, why = cut_neck(V, F, neck)
    assert why == "" and (surgery.components_before, surgery.components_after) == (1, 2)
    V2, F2 = surgery.vertices, surgery.faces
    count, labels = vertex_components(F2, len(V2))
    chi, closed = component_topology(F2, labels, count)
    assert count == 2 and chi.tolist() == [2, 2] and closed.all() and _oriented(F2)
    # symmetric halves; the neck's thin part (16 vertices, their 64 triangles) removed,
    # each loop (16 edges at about 0.07 from the axis) capped by a dome of 33 points
    # and 80 triangles
    assert np.bincount(labels).tolist() == [1298, 1298]
    assert (~surgery.keep_vertices).sum() == 16 and (~surgery.keep_faces).sum() == 64
    assert len(V2) == len(V) - 16 + 66 and len(F2) == len(F) - 64 + 160
    assert metrics.min_angle(V2, F2) > metrics.min_angle(V, F)           # 13.8 > 5.0 degrees
    assert np.array_equal(F2[: surgery.keep_faces.sum()],
                          (np.cumsum(surgery.keep_vertices) - 1)[F[surgery.keep_faces]])
    # the band within r_band of the axis and z_band of the plane: a tube's area at most
    r, z = surgery.band_radius, surgery.band_height
    assert r < h and z < 2 * neck.radius + 2 * h
    assert 0.1 < surgery.band_area <= 4 * np.pi * r * z                 # 0.131 <= 0.179
    assert 0 < surgery.area_removed <= surgery.band_area
    assert surgery.area_removed == pytest.approx(
        metrics.area(V, F) - metrics.area(V2, F2), abs=1e-12)
    assert 0 < surgery.volume_removed < 2 * np.pi * r ** 2 * z
    assert surgery.area_removed < 6e-3 * metrics.area(V, F)             # 0.082 of 15.3
    # the domes inside the band's tube, one on each side of the plane
    new = V2[surgery.keep_vertices.sum():]
    assert np.linalg.norm(new[:, :2], axis=1).max() < r and np.abs(new[:, 2]).max() < z
    assert (new[:, 2] > 0).sum() == (new[:, 2] < 0).sum() == 33


def test_a_cut_that_does_not_separate_is_refused(dumbbell):
    V, F, _ = dumbbell
    neck = find_neck(V, F)
    far = neck._replace(vertex=int(np.argmax(V[:, 2])))                    # a bulb's pole
    surgery, why = cut_neck(V, F, far)
    assert surgery is None and why
