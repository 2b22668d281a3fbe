"""A surface or component shrunk to a point or a line (mcfbench/geometry/collapse.py), and
the driver's check of it before every solve: every scheme of the registry ends such a
run ``degenerated``, naming the component and the time (issue #24)."""

import igl
import numpy as np
import pytest

from mcfbench.cli import main
from mcfbench.geometry.collapse import AREA_TOL, CollapseCheck
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
    assert point.startswith("component 0 of 1 (162 vertices") and "shrank to a point" in point
    line = check(V * [1e-4, 1e-4, 1.0])       # area 2e-4 of its initial, diameter 0.58
    assert "shrank to a line" in line and "area" in line
    bad = V.copy()
    bad[7, 1] = np.nan
    assert check(bad) == "non-finite coordinates at 1 vertex(es), e.g. vertex 7 of component 0 of 1"
    assert check(np.sqrt(AREA_TOL) * 1.01 * V) is None    # area ratio just above the tolerance


def test_the_smaller_component_is_named():
    V, F = two_spheres()
    W = V.copy()
    W[162:] = 0.01 * (W[162:] - [3.0, 0.0, 0.0]) + [3.0, 0.0, 0.0]
    detail = CollapseCheck(V, F)(W)
    assert detail.startswith("component 1 of 2 (162 vertices, e.g. vertex 162) shrank to a point")


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
    0.0014): 8 triangles fold at step 3, before the cube has shrunk to a point; and KLL,
    which folds at its first step (below)."""
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
    if scheme == "mdr":
        assert traj.status == "inverted" and traj.failed_step == 3, traj.message
        assert "8 triangle(s) inverted" in traj.message
        return
    assert traj.status == "degenerated", traj.message
    assert "component 0 of 1 (8 vertices, e.g. vertex 0) shrank to a point" in traj.message
    assert traj.message.startswith(f"degenerated at step {traj.failed_step} (t = ")


@pytest.mark.parametrize("scheme", list(SCHEMES))
def test_sphere_past_its_extinction_time_degenerates(scheme):
    """R = 1, extinction at R^2 / 4 = 0.25; 40 steps of 0.01 reach t = 0.4. The
    schemes lag the exact radius a little: the check fires at t = 0.28-0.29 (KLL:
    below; BGN/BDF2 0.26, BGN/BDF3 0.25 itself)."""
    V, F = icosphere(2)
    traj = simulate(SCHEMES[scheme].make(V, F, 0.01), 40, save_every=0)
    if scheme == "kll":
        # its velocity -H nu (H = 2 / r evolved, explicit in X) carries the vertices
        # through the centre at t = 0.26 before the sphere is small enough to count as a
        # point (radius 0.09 at t = 0.25): the area check ends it
        assert traj.status == "area_grew" and traj.t_failed == pytest.approx(0.26), \
            traj.message
        return
    assert traj.status == "degenerated", traj.message
    assert 0.25 <= traj.t_failed < 0.3 and "shrank to a point" in traj.message


def test_collapse_ends_the_run_in_record_mode_too():
    V, F = icosphere(2)
    traj = simulate(SCHEMES["cotan"].make(V, F, 0.01), 40, on_defect="record", save_every=0)
    assert traj.status == "degenerated" and traj.steps_done < 30


def test_smaller_sphere_is_named_with_its_time():
    """The sphere of radius 0.3 vanishes at t = 0.0225, the unit sphere goes on."""
    V, F = two_spheres()
    traj = simulate(SCHEMES["cotan"].make(V, F, 0.001), 60, save_every=0)
    assert traj.status == "degenerated" and 0.0225 < traj.t_failed < 0.03
    assert "component 1 of 2" in traj.message


def test_command_line_names_the_collapse(tmp_path, capsys):
    mesh, out = tmp_path / "cube.obj", tmp_path / "run.npz"
    igl.write_triangle_mesh(str(mesh), CUBE_V, CUBE_F)
    code = main(["run", str(mesh), "--scheme", "cotan", "--tau-edge", "0.1", "--steps", "10",
                 "--out", str(out)])
    assert code == 1 and "error: degenerated at step 4 (t = 0.518082): component 0 of 1" \
        in capsys.readouterr().err
    assert str(np.load(out)["status"]) == "degenerated"
