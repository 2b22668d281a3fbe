"""The re-extraction of a surface without its parts thinner than the mesh
(mcfbench.geometry.reextraction) and NAME+surgery's use of it (the run goes on, or
ends extinct when nothing is left)."""

import igl
import numpy as np
import pytest

from mcfbench.geometry import metrics
from mcfbench.geometry.reextraction import (
    GRID, OPENING, REACH, SHARPNESS, convex_sharpness, open_surface, sharpness,
    signed_mean_curvature)
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.remeshing import mesh_hook
from mcfbench.running.schemes import get_scheme


@pytest.fixture(scope="module")
def sphere():
    V, F = icosphere(3)
    return V, F, metrics.mean_edge_length(V, F)


def test_the_signed_mean_curvature_of_the_unit_sphere_is_two(sphere):
    V, F, h = sphere
    H = signed_mean_curvature(V, F)
    assert np.allclose(H, 2.0, rtol=0.02)
    assert np.allclose(signed_mean_curvature(V, F[:, ::-1]), -2.0, rtol=0.02)
    assert sharpness(V, F, h)[0] == pytest.approx(2 * h, rel=0.02)
    assert 2 * h < SHARPNESS


def test_a_surface_thicker_than_the_opening_is_kept(sphere):
    """The unit sphere (radius 1 = 12 h) comes back within marching cubes' error: area
    and volume within 1 %, one component."""
    V, F, h = sphere
    opened, reason = open_surface(V, F, h)
    assert reason == "" and (opened.components_before, opened.components_after) == (1, 1)
    assert abs(opened.area_removed) < 0.01 * metrics.area(V, F)
    assert abs(opened.volume_removed) < 0.01 * metrics.volume(V, F)
    radius = np.linalg.norm(opened.vertices, axis=1)
    assert np.abs(radius - 1).max() < 0.3 * h


def test_a_part_thinner_than_the_opening_is_removed_and_the_rest_kept(sphere):
    """A second sphere of radius 0.6 h (< OPENING h) beside the unit one vanishes, its
    area (about 4 pi (0.6 h)^2) the area removed within marching cubes' error."""
    V, F, h = sphere
    r = 0.6 * h * OPENING
    U, G = icosphere(2, radius=r)
    both = np.vstack([V, U + [3.0, 0, 0]]), np.vstack([F, G + len(V)])
    opened, reason = open_surface(*both, h)
    assert reason == "" and (opened.components_before, opened.components_after) == (2, 1)
    assert opened.area_removed == pytest.approx(metrics.area(U, G), abs=0.01 * 4 * np.pi)
    assert np.linalg.norm(opened.vertices, axis=1).max() < 1 + h


def test_an_open_mesh_is_refused(sphere):
    V, F, h = sphere
    opened, reason = open_surface(V, F[1:], h)
    assert opened is None and "open" in reason


def test_a_sheet_thinner_than_the_mesh_is_left_to_the_flow():
    """A flat ellipsoid (half-thickness 0.05 against h = 0.3) is thinner than the mesh
    everywhere: the opening would leave nothing, so it is refused (the flow takes the
    surface to its own extinction), once, and not asked again on the same mesh."""
    V, F = icosphere(2)
    V = V * [1.0, 1.0, 0.05]
    h = metrics.mean_edge_length(V, F)
    assert sharpness(V, F, h)[0] > SHARPNESS
    opened, reason = open_surface(V, F, h)
    assert opened is None and "left to the flow" in reason
    scheme = get_scheme("bgn+surgery")
    traj = simulate(scheme.make(V, F, 0.1 * h * h), 3, remesh=mesh_hook(scheme, (V, F)))
    refused = [e for e in traj.events if e["event"] == "refused" and e["by"] == "Reextractor"]
    assert [e["step"] for e in refused] == [0]
    assert "left to the flow" in refused[0]["why"]
    assert not [e for e in traj.events if e["event"] == "reextracted"]


def test_a_thin_fin_loses_its_rim_and_keeps_its_middle():
    """The unit ball with a flat fin (a disk 0.1 thick, reaching out to x = 1.9)
    joined to it, meshed by marching cubes: the fin is thinner than 2 h and its rim is
    sharp; the opening takes the fin within REACH h of its sharp vertices (the rim's
    band), keeps its middle (farther out than the ball) and the ball's far side within
    0.5 h of the unit sphere (the grid h)."""
    from mcfbench.geometry.implicit import isosurface

    def field(x, y, z):
        fin = 1 - ((x - 1.3) / 0.6) ** 2 - (y / 0.6) ** 2 - (z / 0.05) ** 2
        return np.maximum(1 - np.sqrt(x * x + y * y + z * z), 0.05 * fin)

    V, F = isosurface(field, [-1.2, -1.2, -1.2], [2.1, 1.2, 1.2], 50)
    h = metrics.mean_edge_length(V, F)
    assert 0.1 < 2 * h and V[:, 0].max() > 1.8
    opened, reason = open_surface(V, F, h, grid=1.0)     # a coarser grid: a quick test
    assert reason == "" and (opened.components_before, opened.components_after) == (1, 1)
    U = opened.vertices
    assert 1.0 + 2 * h < U[:, 0].max() < 1.9 - (REACH - 1) * h
    far = U[U[:, 0] < 0]
    assert np.abs(np.linalg.norm(far, axis=1) - 1).max() < 0.5 * h
    assert opened.area_removed > 0


@pytest.fixture(scope="module")
def barbell():
    """Two unit balls joined by a rod of radius 0.3 (thinner than 2 h, h = 0.4, not sharp:
    H h = 1.3), the left one with a spike of radius 0.1 (H h = 4) sticking out 0.5 from
    it, meshed by marching cubes on a grid of 0.09."""
    from mcfbench.geometry.implicit import isosurface

    def field(x, y, z):
        rod = np.minimum(0.3 - np.hypot(y, z), 1.0 - np.abs(x))
        spike = np.minimum(0.1 - np.hypot(x + 1.5, z), 0.75 - np.abs(y - 0.75))
        return np.maximum.reduce([1 - np.sqrt((x + 1.5) ** 2 + y * y + z * z),
                                  1 - np.sqrt((x - 1.5) ** 2 + y * y + z * z), rod, spike])

    V, F = isosurface(field, [-2.7, -1.2, -1.2], [2.7, 1.8, 1.2], 60)
    return V, F, 0.4


def test_the_opening_is_local_a_spike_removed_and_a_thin_rod_kept(barbell):
    """The spike is removed, its area (2 pi 0.1 (0.5 - the tolerance GRID h / 2 at its
    foot)) within 10 %; the rod, which the opening of the whole solid would cut, is kept
    (one component); the surface farther than (REACH + 1) h from the spike's foot is the
    input's within 0.1 h (marching cubes on the grid GRID h: O(h^2))."""
    V, F, h = barbell
    sharp = convex_sharpness(V, F, h) > SHARPNESS
    assert (V[sharp, 1] > 1.0).any()                # the spike (and a few slivers)
    opened, reason = open_surface(V, F, h)
    assert reason == "" and (opened.components_before, opened.components_after) == (1, 1)
    U = opened.vertices
    assert U[:, 1].max() < 1.0 + 0.1 * h and (np.abs(U[:, 0]) < 0.5).any()
    spike = 2 * np.pi * 0.1 * (0.5 - GRID * h / 2)
    assert opened.area_removed == pytest.approx(spike, rel=0.1)
    far = U[np.linalg.norm(U - [-1.5, 1.0, 0.0], axis=1) > (REACH + 1) * h]
    assert np.sqrt(igl.point_mesh_squared_distance(far, V, F)[0]).max() < 0.1 * h


def test_a_pinched_neck_that_was_not_cut_is_opened_there(barbell):
    """Given the rod's middle as a neck's points, the opening cuts the rod there: two
    components, and less area removed than the rod's whole side (2 pi 0.3 2)."""
    V, F, h = barbell
    opened, reason = open_surface(V, F, h, necks=[[0.0, 0.0, 0.0]])
    assert reason == "" and (opened.components_before, opened.components_after) == (1, 2)
    assert 0 < opened.area_removed < 2 * np.pi * 0.3 * 2.0


def test_a_piece_cut_on_both_sides_goes_with_the_cuts(barbell):
    """Necks on the rod's axis at x = +-0.45, a reach of h: the opening cuts the rod at
    both ends and its middle, a piece thinner than the opening between the cuts (three
    components otherwise), goes too: two components (the balls), nothing left near the
    rod's middle, more area removed than the middle's side (|x| < 0.3)."""
    V, F, h = barbell
    opened, reason = open_surface(V, F, h, necks=[[-0.45, 0, 0], [0.45, 0, 0]], reach=1.0)
    assert reason == "" and (opened.components_before, opened.components_after) == (1, 2)
    assert not (np.abs(opened.vertices[:, 0]) < 0.3).any()
    assert opened.area_removed > 2 * np.pi * 0.3 * 0.6


def test_a_vanishing_small_part_is_removed_and_the_run_goes_on(sphere):
    """The unit sphere with a small sphere of radius 0.25 h beside it (its max H h = 8):
    bgn+surgery removes the small one at step 0 and flows the unit sphere on, status
    ok, its area share removed the small sphere's."""
    V, F, h = sphere
    U, G = icosphere(1, radius=0.25 * h)
    W, E = np.vstack([V, U + [3.0, 0, 0]]), np.vstack([F, G + len(V)])
    scheme = get_scheme("bgn+surgery")
    traj = simulate(scheme.make(W, E, 0.1 * h * h), 4, remesh=mesh_hook(scheme, (W, E)))
    assert traj.status == "ok", traj.message
    opened = [e for e in traj.events if e["event"] == "reextracted"]
    assert len(opened) == 1 and opened[0]["step"] == 0
    assert (opened[0]["components_before"], opened[0]["components_after"]) == (2, 1)
    assert 0 < opened[0]["area_share"] < 0.02
    assert np.linalg.norm(traj.flow.vertices, axis=1).max() < 1.0
