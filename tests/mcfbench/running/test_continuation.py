"""A run that loses one closed component of several goes on with the rest
(mcfbench/running/continuation.py, the driver's ``rebuild``; issue #44, item 3)."""

from functools import partial

import numpy as np
import pytest

from mcfbench.geometry.spheres import icosphere
from mcfbench.running.continuation import STATE_ONLY, sub_flow, sub_mesh, why_not
from mcfbench.running.driver import simulate
from mcfbench.running.problems import Problem
from mcfbench.running.run import run
from mcfbench.running.schemes import SCHEMES, TANGENTIAL, get_scheme


def two_spheres():
    """Unit sphere around the origin and a sphere of radius 0.3 around (3, 0, 0)."""
    V, F = icosphere(2)
    return np.vstack([V, 0.3 * V + [3.0, 0.0, 0.0]]), np.vstack([F, F + len(V)])


def test_sub_mesh_keeps_whole_triangles_renumbered():
    V, F = two_spheres()
    keep = np.arange(len(V)) >= 162
    faces, kept = sub_mesh(F, keep)
    assert kept.tolist() == [False] * 320 + [True] * 320
    assert np.array_equal(faces, F[320:] - 162)


@pytest.mark.parametrize("scheme", ["cotan", "bgn", "ddfv-chord-carried"])
def test_the_run_goes_on_without_the_smaller_sphere(scheme):
    """The sphere of radius 0.3 vanishes first (R^2 / 4 = 0.0225; 0.0237-0.0244 at tau =
    0.001), then the unit sphere, its extinction time as that of the unit sphere alone;
    the frames keep the initial layout, the small sphere's points where it vanished."""
    V, F = two_spheres()
    entry = SCHEMES[scheme]
    traj = simulate(entry.make(V, F, 0.001), 400, save_every=100,
                    rebuild=partial(sub_flow, entry))
    alone = simulate(entry.make(V[:162], F[:320], 0.001), 400, save_every=0)
    assert traj.status == alone.status == "extinct", traj.message
    small, big = traj.events
    assert small["component"] == 1 and big["component"] == 0
    assert 0.0225 < small["extinction_time"] < 0.0245 and small["kind"] == "point"
    assert small["area"] < 0.25 * 4 * np.pi * 0.09 and small["volume"] > 0
    assert big["extinction_time"] == pytest.approx(alone.extinction_time, abs=2e-3)
    assert traj.message.startswith(f"extinct at step {big['step']}")
    assert "component 0 of 2 (162 vertices, e.g. vertex 0)" in traj.message
    frames = traj.frames["vertices"]
    assert frames.shape[1:] == (324, 3) and np.array_equal(traj.faces, F)
    assert traj.steps.tolist()[:3] == [0, 100, 200]
    assert np.array_equal(frames[1, 162:], frames[-1, 162:])         # frozen since step 24
    assert np.linalg.norm(frames[-1, 162:] - [3.0, 0.0, 0.0], axis=1).max() < 0.1
    assert np.linalg.norm(frames[-1, :162], axis=1).max() < 0.2
    if entry.extra_points:
        assert traj.frames["extra_points"].shape[1:] == (640, 3)


@pytest.mark.parametrize("scheme", ["kll", "cmcf", "deturck", "cotan@bdf2"])
def test_schemes_that_keep_initial_state_end_saying_why(scheme):
    """(The redistributing schemes refuse a surface of several components to begin with.)"""
    entry = get_scheme(scheme)
    V, F = two_spheres()
    traj = simulate(entry.make(V, F, 0.001), 60, save_every=0, integrator=entry.integrator,
                    rebuild=partial(sub_flow, entry))
    assert traj.status == "degenerated" and "cannot go on without it" in traj.message
    assert traj.events[0]["why_not"] == why_not(entry) and "component 1 of 2" in traj.message


def test_which_schemes_go_on():
    assert set(STATE_ONLY) < set(TANGENTIAL)
    going = sorted(name for name, entry in SCHEMES.items() if why_not(entry) is None)
    assert going == ["bgn", "cotan", "cotan-intrinsic", "cotan-voronoi", "ddfv", "ddfv-chord",
                     "ddfv-chord-bgn-carried", "ddfv-chord-carried",
                     "ddfv-chord-eliminate", "ddfv-chord-mdr-carried", "ddfv-eliminate",
                     "mdr"]
    assert "bdf2" in why_not(get_scheme("cotan@bdf2"))
    assert "integrates in time itself" in why_not(get_scheme("bgn-bdf2"))


def test_run_goes_on_and_records_the_whole_mesh():
    """Through :func:`mcfbench.running.run.run`: the record counts the initial mesh's
    points, its end is the unit sphere's extinction."""
    V, F = two_spheres()
    result, traj = run("cotan", Problem.user_mesh("two spheres", 400), 0, mesh=(V, F),
                       tau=0.001)
    assert result.status == "extinct" and result.nV == result.nF == 324
    assert [e["component"] for e in traj.events] == [1, 0]
    assert 0.25 < traj.extinction_time < 0.256
