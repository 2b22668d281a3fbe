"""A surface or component shrunk to a point or a line (mcfbench/geometry/collapse.py), and
the driver's check of it before every solve: every scheme of the registry ends such a
run ``degenerated``, naming the component and the time (issue #24), unless it vanished
round, to a point or a circle: ``extinct``, the flow's end (issue #44, item 3)."""

import igl
import numpy as np
import pytest

from mcfbench.cli import main
from mcfbench.geometry import metrics
from mcfbench.geometry.collapse import (AREA_TOL, ROUND_POINT, ROUND_TUBE, WATCH,
                                        CollapseCheck, tube_fit)
from mcfbench.geometry.committed_meshes import read_committed_mesh
from mcfbench.geometry.shapes import cylinder, torus
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.driver import simulate
from mcfbench.running.schemes import SCHEMES
from mcfbench.running.solver import Solver

CUBE_V = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
CUBE_F = np.array([[0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6], [0, 1, 5], [0, 5, 4],
                   [1, 3, 7], [1, 7, 5], [3, 2, 6], [3, 6, 7], [2, 0, 4], [2, 4, 6]])
"""The unit cube as 12 outward-oriented triangles (issue #24)."""


def two_spheres():
    """Unit sphere around the origin and a sphere of radius 0.3 around (3, 0, 0)."""
    V, F = icosphere(2)
    return np.vstack([V, 0.3 * V + [3.0, 0.0, 0.0]]), np.vstack([F, F + len(V)])


def test_intact_surface_passes_at_any_scale():
    V, F = two_spheres()
    for scale in (1e-6, 1.0, 1e6):
        assert CollapseCheck(scale * V, F)(0.5 * scale * V) is None


def test_point_line_and_non_finite_are_named():
    V, F = icosphere(2)
    check = CollapseCheck(V, F)
    point = check(1e-3 * V)
    assert point.status == "extinct" and point.kinds == ("point",), point.detail
    assert str(point).startswith("component 0 of 1 (162 vertices, e.g. vertex 0) vanished "
                                 "round, to a point")
    line = check(V * [1e-4, 1e-4, 1.0])       # area 2e-4 of its initial, diameter 0.58
    assert line.status == "degenerated" and "shrank to a line" in str(line)
    bad = V.copy()
    bad[7, 1] = np.nan
    assert str(check(bad)) == \
        "non-finite coordinates at 1 vertex(es), e.g. vertex 7 of component 0 of 1"
    assert check(bad).status == "degenerated"
    # no time step given: a round sphere is extinct only once it collapsed
    assert check(np.sqrt(AREA_TOL) * 1.01 * V) is None


def test_a_flattened_collapse_is_not_an_extinction():
    """A spheroid of axes 5:5:1 shrunk to a point: isoperimetric ratio 0.24, below
    ROUND_POINT; as are a cube's (pi / 6) and a tetrahedron's."""
    V, F = icosphere(2)
    flat = CollapseCheck(V, F)(1e-3 * V * [1.0, 1.0, 0.2])
    assert flat.status == "degenerated" and "shrank to a point" in str(flat), str(flat)
    assert metrics.volume(V * [1, 1, 0.2], F) ** 2 * 36 * np.pi \
        / metrics.area(V * [1, 1, 0.2], F) ** 3 < 0.25 < ROUND_POINT
    cube = CollapseCheck(CUBE_V, CUBE_F)(1e-3 * CUBE_V)
    assert cube.status == "degenerated" and 36 * np.pi / 6 ** 3 < ROUND_POINT


@pytest.mark.parametrize("scale", [0.2, 0.05])
def test_a_round_sphere_with_two_steps_left_is_extinct(scale):
    """Area A = s^2 A_0 of the icosphere: A / (16 pi) left, extinct when that is below
    two time steps (before its area reaches AREA_TOL), at t plus it."""
    V, F = icosphere(2)
    left = scale ** 2 * metrics.area(V, F) / (16 * np.pi)
    check = CollapseCheck(V, F, tau=0.51 * left)
    found = check(scale * V, t=0.2)
    assert found.status == "extinct" and found.components == (0,), str(found)
    assert found.times[0] == pytest.approx(0.2 + left, rel=1e-12)
    assert found.areas[0] == pytest.approx(scale ** 2 * metrics.area(V, F), rel=1e-12)
    assert found.volumes[0] == pytest.approx(scale ** 3 * metrics.volume(V, F), rel=1e-12)
    assert f"extinct at t = {0.2 + left:.6g}" in str(found)
    assert CollapseCheck(V, F, tau=0.49 * left)(scale * V, t=0.2) is None


def thin_torus(r, squash=1.0):
    """The torus (2, 0.5) of the problem's level 1 and the same mesh with tube radius
    ``r``, its tube's height ``squash`` times that (an elliptic tube for squash < 1)."""
    V0, F = torus(2.0, 0.5, 32, 8)
    V, _ = torus(2.0, r, 32, 8)
    return V0, F, V * [1.0, 1.0, squash]


def test_a_thin_round_torus_vanishes_to_a_circle():
    """A tube of radius r = 0.02 about the circle of radius 2 (area 4 % of the initial
    torus's): a round tube (octagons: 2 V / A = 0.922 r), r^2 / 2 left with r = 2 V / A."""
    V0, F, V = thin_torus(0.02)
    assert metrics.area(V, F) / metrics.area(V0, F) < WATCH
    tube = 2 * metrics.volume(V, F) / metrics.area(V, F)
    assert tube == pytest.approx(0.9217 * 0.02, rel=1e-3)
    found = CollapseCheck(V0, F, tau=0.51 * tube ** 2 / 2)(V, t=0.1)
    assert found.status == "extinct" and found.kinds == ("circle",), str(found)
    assert found.times[0] == pytest.approx(0.1 + tube ** 2 / 2, rel=1e-9)
    assert "vanished round, to a circle" in str(found)
    assert CollapseCheck(V0, F, tau=0.49 * tube ** 2 / 2)(V, t=0.1) is None
    R, r, spread = tube_fit(V)
    assert R == pytest.approx(2.0, rel=1e-12) and r == pytest.approx(0.02, rel=1e-9)
    assert spread < 1e-9


def test_a_flattened_tube_is_not_a_circle():
    """The tube squashed to an ellipse of axes 5:1: not round (its points 0.2 r to r from
    the circle), so no extinction before it collapses, and a breakdown after."""
    V0, F, V = thin_torus(0.02, squash=0.2)
    assert tube_fit(V)[2] > ROUND_TUBE
    assert CollapseCheck(V0, F, tau=1.0)(V, t=0.1) is None
    V0, F, V = thin_torus(1e-4, squash=0.2)
    found = CollapseCheck(V0, F, tau=1.0)(V, t=0.1)
    assert found.status == "degenerated" and "shrank to a line" in str(found), str(found)
    # an open surface (a cylinder: Euler characteristic 0, as a torus's) never vanishes round
    C, G = cylinder(around=24, along=8, radius=1.0, half_height=0.5)
    assert CollapseCheck(C, G, tau=1.0)(0.01 * C).status == "degenerated"


def trefoil_tube(r, along=120, around=8):
    """A tube of radius ``r`` about the trefoil knot ``(sin s + 2 sin 2s, cos s - 2 cos 2s,
    -sin 3s)`` (its Frenet frame; curvature radius at least 0.5), outward oriented."""
    s = 2 * np.pi * np.arange(along) / along
    c = np.stack([np.sin(s) + 2 * np.sin(2 * s), np.cos(s) - 2 * np.cos(2 * s),
                  -np.sin(3 * s)], axis=1)
    d1 = np.stack([np.cos(s) + 4 * np.cos(2 * s), -np.sin(s) + 4 * np.sin(2 * s),
                   -3 * np.cos(3 * s)], axis=1)
    d2 = np.stack([-np.sin(s) - 8 * np.sin(2 * s), -np.cos(s) + 8 * np.cos(2 * s),
                   9 * np.sin(3 * s)], axis=1)
    T = d1 / np.linalg.norm(d1, axis=1)[:, None]
    N = d2 - (d2 * T).sum(axis=1)[:, None] * T
    N /= np.linalg.norm(N, axis=1)[:, None]
    B = np.cross(T, N)
    theta = 2 * np.pi * np.arange(around) / around
    V = (c[:, None] + r * (np.cos(theta)[None, :, None] * N[:, None]
                           + np.sin(theta)[None, :, None] * B[:, None])).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(along), np.arange(around), indexing="ij")
    a, b = i * around + j, i * around + (j + 1) % around
    c2, d = (i + 1) % along * around + j, (i + 1) % along * around + (j + 1) % around
    F = np.concatenate([np.stack([a, c2, d], -1), np.stack([a, d, b], -1)]).reshape(-1, 3)
    return V, (F if metrics.volume(V, F) > 0 else F[:, ::-1])


def test_a_thin_round_tube_about_a_knot_vanishes_to_a_curve():
    """A tube of radius 0.05 about the trefoil (20 % of the area of the same tube of
    radius 0.25): no planar circle fits it, but its mean curvature is 1 / r within
    ROUND_TUBE, r = 2 V / A (0.92 of the octagons' radius): extinct, to a curve, with
    r^2 / 2 left; squashed to an ellipse of axes 3:1 it is not round."""
    V0, F = trefoil_tube(0.25)
    V, _ = trefoil_tube(0.05)
    assert metrics.area(V, F) / metrics.area(V0, F) < WATCH
    tube = 2 * metrics.volume(V, F) / metrics.area(V, F)
    assert tube_fit(V)[1] > 10 * tube          # no planar circle: far from the best one
    assert tube == pytest.approx(0.92 * 0.05, rel=0.01)
    found = CollapseCheck(V0, F, tau=0.51 * tube ** 2 / 2)(V, t=0.1)
    assert found.status == "extinct" and found.kinds == ("curve",), str(found)
    assert found.times[0] == pytest.approx(0.1 + tube ** 2 / 2, rel=1e-9)
    assert "vanished round, to a curve" in str(found)
    assert CollapseCheck(V0, F, tau=0.49 * tube ** 2 / 2)(V, t=0.1) is None
    centre = np.repeat(trefoil_tube(1e-9)[0].reshape(-1, 8, 3).mean(axis=1), 8, axis=0)
    flat = centre + (V - centre) * [1.0, 1.0, 1 / 3]     # not round about its curve
    assert CollapseCheck(V0, F, tau=1.0)(flat, t=0.1) is None


def test_euler_characteristics_of_the_components():
    V, F = two_spheres()
    T, G = torus(2.0, 0.5, 16, 4)
    W, H = np.vstack([V, T]), np.vstack([F, G + len(V)])
    check = CollapseCheck(W, H)
    assert list(check.chi) == [2, 2, 0] and check.closed.all()


def test_the_smaller_component_is_named():
    V, F = two_spheres()
    W = V.copy()
    W[162:] = 0.01 * (W[162:] - [3.0, 0.0, 0.0]) + [3.0, 0.0, 0.0]
    found = CollapseCheck(V, F)(W)
    assert str(found).startswith("component 1 of 2 (162 vertices, e.g. vertex 162) vanished "
                                 "round, to a point")
    assert found.components == (1,)


@pytest.mark.parametrize("scheme", list(SCHEMES))
def test_cube_of_twelve_triangles_degenerates(scheme):
    """tau = 0.1 h^2 with 12 triangles: the cube vanishes in a few steps; every scheme
    ends ``degenerated`` before the solve (before, DDFV and BGN ended ``solver_stagnated``
    and the cotangent kernel divided by zero), except the DDFV schemes with the
    elimination (3.6) or MDR's tangential motion of the F-vertices (ddfv-chord-mdr-carried:
    the least deformation, close to no tangential motion; distance from the centre 0.195
    and 0.212 at step 3, the elimination 0.157 and 0.185), whose mesh of F-vertices folds
    at step 3, before it has shrunk to a point (``inverted``, the driver's invariant
    check), and MDR, whose valence-4
    corners run ahead of the valence-5 ones (distance from the centre 0.20 against 0.29
    at step 3; BGN, whose unnormalised normals make it shrink faster here, 0.0012 and
    0.0014): 8 triangles fold at step 3, before the cube has shrunk to a point (dual-MDR,
    with MDR's tangential motion: 12 at step 3); and KLL, which folds at its first step
    (below)."""
    h = igl.edge_lengths(CUBE_V, CUBE_F).mean()
    flow = SCHEMES[scheme].make(CUBE_V, CUBE_F, 0.1 * h ** 2)
    traj = simulate(flow, 10, solver=Solver("direct"), save_every=0)
    if scheme == "kll":            # its velocity -H nu is explicit in X: one step of
        # dt H = 0.26-0.32 moves the corners along vertex normals that are not radial on
        # these triangles (distance from the centre 0.87 -> 0.48-0.51)
        assert traj.status == "inverted" and traj.failed_step == 1, traj.message
        assert "4 triangle(s) inverted" in traj.message
        return
    # BGN/BDF-k (baselines.bgn_bdf, second step BDF2's: as bgn@bdf2) at step 2
    first = 2 if SCHEMES[scheme].integrates_itself else 3
    assert first <= traj.failed_step <= 5 and traj.steps_done == traj.failed_step
    if scheme.endswith("eliminate") or scheme == "ddfv-chord-mdr-carried":
        assert traj.status == "inverted" and traj.failed_step == 3, traj.message
        assert "12 triangle(s) folded that were not at step 0" in traj.message
        return
    if scheme in ("mdr", "dual-mdr"):
        assert traj.status == "inverted" and traj.failed_step == 3, traj.message
        folded = {"mdr": 8, "dual-mdr": 12}[scheme]
        assert f"{folded} triangle(s) inverted" in traj.message
        return
    assert traj.status == "degenerated", traj.message
    assert "component 0 of 1 (8 vertices, e.g. vertex 0) shrank to a point" in traj.message
    assert traj.message.startswith(f"degenerated at step {traj.failed_step} (t = ")


@pytest.mark.parametrize("scheme", list(SCHEMES))
def test_sphere_past_its_extinction_time_is_extinct(scheme):
    """R = 1, extinction at R^2 / 4 = 0.25; 40 steps of 0.01 would reach t = 0.4. Every
    scheme ends ``extinct`` (before, ``degenerated`` at t = 0.28-0.29, KLL ``area_grew``
    at 0.26) once less than two steps are left: at t = 0.25, its extinction time
    0.263-0.268 (the schemes lag the exact radius at tau = 0.01; KLL, whose explicit
    velocity runs ahead, at t = 0.23, 0.2496; BGN/BDF2 and BGN/BDF3, second order in
    time on the inscribed mesh, at t = 0.23, 0.2449 and 0.2431)."""
    V, F = icosphere(2)
    traj = simulate(SCHEMES[scheme].make(V, F, 0.01), 40, save_every=0)
    assert traj.status == "extinct", traj.message
    assert "vanished round, to a point" in traj.message
    ahead = scheme == "kll" or SCHEMES[scheme].integrates_itself
    assert traj.t_failed == pytest.approx(0.23 if ahead else 0.25)
    assert (0.24 if ahead else 0.249) < traj.extinction_time < 0.27
    [event] = traj.events
    assert event["component"] == 0 and event["kind"] == "point"
    assert event["extinction_time"] == traj.extinction_time


def test_extinction_ends_the_run_in_record_mode_too():
    V, F = icosphere(2)
    traj = simulate(SCHEMES["cotan"].make(V, F, 0.01), 40, on_defect="record", save_every=0)
    assert traj.status == "extinct" and traj.steps_done == 25


def test_smaller_sphere_without_a_continuation_ends_the_run():
    """The sphere of radius 0.3 vanishes at t = 0.0225, the unit sphere would go on: with
    no ``rebuild`` (:mod:`mcfbench.running.continuation`) the run cannot, and says so."""
    V, F = two_spheres()
    traj = simulate(SCHEMES["cotan"].make(V, F, 0.001), 60, save_every=0)
    assert traj.status == "degenerated" and 0.0215 < traj.t_failed < 0.024, traj.message
    assert "component 1 of 2" in traj.message and "cannot go on without it" in traj.message
    assert traj.events[0]["continued"] is False


def test_command_line_names_the_collapse(tmp_path, capsys):
    mesh, out = tmp_path / "cube.obj", tmp_path / "run.npz"
    igl.write_triangle_mesh(str(mesh), CUBE_V, CUBE_F)
    code = main(["run", str(mesh), "--scheme", "cotan", "--tau-edge", "0.1", "--steps", "10",
                 "--out", str(out)])
    assert code == 1 and "error: degenerated at step 4 (t = 0.518082): component 0 of 1" \
        in capsys.readouterr().err
    assert str(np.load(out)["status"]) == "degenerated"


@pytest.mark.parametrize("name, scheme, kind, step", [
    ("rounded_cube", "bgn", "point", 109), ("nut", "cotan", "circle", 25)])
def test_real_closed_meshes_shrink_to_their_extinction(name, scheme, kind, step):
    """Two committed CAD meshes run long at tau = 0.1 h^2 (the new user's
    ``--tau-edge 0.1``): the rounded cube (genus 0) shrinks round to a point (cotan folds
    it first, ``inverted`` at step 79), the octagonal nut (genus 1) to the circle of its
    ring (its tube round; before: ``degenerated``, a line)."""
    V, F = read_committed_mesh(name)
    tau = 0.1 * igl.edge_lengths(V, F).mean() ** 2
    traj = simulate(SCHEMES[scheme].make(V, F, tau), 400, save_every=0)
    assert traj.status == "extinct" and traj.failed_step == step, traj.message
    [event] = traj.events
    assert event["kind"] == kind and f"vanished round, to a {kind}" in traj.message
    assert 0 < event["extinction_time"] - event["time"] < 2 * tau


def test_component_topology_counts_each_components_euler_characteristic():
    """A sphere (chi 2), a torus (0) and a hemisphere with its rim open (1, not closed)
    in one mesh, their vertices numbered in a shuffled order: each component's own."""
    from mcfbench.geometry.collapse import component_topology
    from mcfbench.geometry.measures import vertex_components
    from mcfbench.geometry.surfaces import make_surface

    parts = [icosphere(2), torus(16, 8), make_surface("hemisphere", rings=4, radius=1.0)]
    V = np.vstack([p[0] for p in parts])
    offsets = np.cumsum([0] + [len(p[0]) for p in parts])
    F = np.vstack([p[1] + o for p, o in zip(parts, offsets)])
    order = np.random.default_rng(1).permutation(len(V))
    new = np.empty_like(order)
    new[order] = np.arange(len(V))
    V, F = V[order], new[F]
    count, labels = vertex_components(F, len(V))
    chi, closed = component_topology(F, labels, count)
    of = [labels[new[o]] for o in offsets[:-1]]           # each part's component
    assert count == 3 and chi[of].tolist() == [2, 0, 1]
    assert closed[of].tolist() == [True, True, False]
