"""Property-based tests (hypothesis) of every scheme of the registry through the one ``run``
(mcfbench/running/run.py) on random surfaces (issue #24).

* Random valid closed meshes: convex hulls of 8-40 random points on a sphere or an
  ellipsoid (axes 0.5-2), scaled by 1e-6 to 1e6, ``tau = c h^2`` with ``c`` in
  [0.001, 0.1]. A few steps of every scheme end ``ok`` or with a named status
  (:data:`mcfbench.storage.statuses.STATUSES`), never an exception.
* The same run agrees with itself under a rigid motion (a rotation by up to about 160
  degrees about any axis and a shift of up to 10 diameters), a relabelling of the vertices, of the triangles and of the corners of
  each triangle, and a scaling: the same status at the same step, and final vertex
  positions equal to :data:`RELATIVE` times the surface's diameter (the redistributing
  schemes: plus :data:`POTENTIAL_RTOL` times the run's largest displacement).
* Random invalid meshes (a valid one with a repeated vertex, a duplicate, a zero-area, a
  non-manifold or a flipped triangle, a vertex index out of range, a NaN coordinate) are
  refused by ``run`` with a :class:`mcfbench.geometry.mesh.MeshError` of the right kind.

Profiles (``tests/conftest.py``): ``ci``, the default, is derandomized (the same examples
on every run) with few examples per test, so this file runs in a few seconds;
``HYPOTHESIS_PROFILE=nightly python -m pytest tests/mcfbench/running/test_run_properties.py`` draws
fresh examples, 25 times as many per test.
"""

import baselines.redistribution
import ddfv.redistribution
import numpy as np
import pytest
from hypothesis import assume, given, note
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from mcfbench.geometry.mesh import MeshError, validate_mesh
from mcfbench.running.problems import Problem
from mcfbench.running.run import run
from mcfbench.running.schemes import SCHEMES
from mcfbench.running.solver import Solver
from mcfbench.storage.statuses import STATUSES

pytestmark = pytest.mark.usefixtures("timed_once")      # what the runs compute, not their time

STEPS = 3
"""Time steps of each run."""

RELATIVE = 1e-8
"""Transformed runs agree to this times the surface's diameter (measured: below 1e-11)."""

POTENTIAL_RTOL = max(baselines.redistribution.POTENTIAL_RTOL, ddfv.redistribution.POTENTIAL_RTOL)
"""The redistribution's potential is solved to this relative residual: whether its CG
iterates once or not at all can turn on round-off, so a redistributing run agrees with
its transformed self only to this fraction of its displacement (measured: 1.9e-7 of the
diameter on a hull of 8 points after 3 steps)."""


def hull_mesh(seed, n, axes):
    """The convex hull of ``n`` random points on the ellipsoid with semi-axes ``axes``,
    outward oriented; ``(V, F)``."""
    rng = np.random.default_rng(seed)
    P = rng.normal(size=(n, 3))
    P = P / np.linalg.norm(P, axis=1, keepdims=True) * np.asarray(axes)
    hull = ConvexHull(P)
    F = hull.simplices.copy()
    normal = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    inward = np.einsum("ij,ij->i", normal, hull.equations[:, :3]) < 0
    F[inward] = F[inward][:, ::-1]
    used = np.unique(F)
    index = np.full(n, -1)
    index[used] = np.arange(len(used))
    return P[used], index[F]


@st.composite
def closed_meshes(draw):
    """A valid closed mesh (convex hull on a sphere or an ellipsoid)."""
    seed = draw(st.integers(0, 2 ** 32 - 1))
    n = draw(st.integers(8, 40))
    ellipsoid = draw(st.booleans())
    axes = draw(st.tuples(*[st.floats(0.5, 2.0)] * 3)) if ellipsoid else (1.0, 1.0, 1.0)
    V, F = hull_mesh(seed, n, axes)
    try:
        V, F = validate_mesh(V, F)
    except MeshError:                      # a sliver hull triangle: rare
        assume(False)
    note(f"hull of {n} points, seed {seed}, axes {axes}")
    return V, F


def rotation(q):
    """The rotation of the (not necessarily unit) quaternion ``q``."""
    w, x, y, z = np.asarray(q) / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


quaternions = st.tuples(*[st.floats(-3.0, 3.0)] * 3).map(lambda v: (1.0, *v))
"""Quaternions ``(1, x, y, z)``: every rotation but the half turns (and near them)."""
scales = st.integers(-6, 6).map(lambda e: 10.0 ** e)
tau_edges = st.floats(0.001, 0.1)


def run_mesh(scheme, V, F, tau_edge):
    """``STEPS`` steps of ``scheme`` on ``(V, F)`` as the command line runs a user's mesh
    (``tau = tau_edge h^2``, the robust solver); ``(result, last vertices)``."""
    problem = Problem.user_mesh("hypothesis", STEPS, tau_edge)
    result, traj = run(scheme, problem, 0, mesh=(V, F), solver=Solver("direct"))
    frames = traj.frames["vertices"]
    return result, frames[-1]


def named(result):
    """The run ended ``ok`` or with a status of the contract and a message naming it."""
    assert result.status in STATUSES, result.status
    if result.status != "ok":
        assert result.message.startswith(f"{result.status} at step "), result.message
    else:
        assert result.message == "" and result.steps_done == STEPS


def agree(result, X, ref, ref_X, atol):
    assert (result.status, result.steps_done) == (ref.status, ref.steps_done), \
        (result.message, ref.message)
    np.testing.assert_allclose(X, ref_X, rtol=0, atol=atol)


@pytest.mark.parametrize("scheme", list(SCHEMES))
@given(mesh=closed_meshes(), scale=scales, q=quaternions,
       shift=st.tuples(*[st.floats(-10.0, 10.0)] * 3), tau_edge=tau_edges,
       seed=st.integers(0, 2 ** 32 - 1))
def test_runs_end_named_and_agree_under_rigid_motion_relabelling_and_scale(
        scheme, mesh, scale, q, shift, tau_edge, seed):
    V, F = mesh
    diameter = np.linalg.norm(V.max(axis=0) - V.min(axis=0))
    ref, ref_X = run_mesh(scheme, V, F, tau_edge)
    named(ref)
    atol = RELATIVE * diameter
    if SCHEMES[scheme].tangential == "redistribute":
        atol += POTENTIAL_RTOL * np.abs(ref_X - V).max()
    # a rigid motion: rotation and a shift of up to 10 diameters
    Q = rotation(q)
    moved, X = run_mesh(scheme, V @ Q.T + np.asarray(shift) * diameter, F, tau_edge)
    named(moved)
    agree(moved, (X - np.asarray(shift) * diameter) @ Q, ref, ref_X, atol)
    # relabelled: vertices, triangles and the corners of each triangle (orientation kept)
    rng = np.random.default_rng(seed)
    perm = rng.permutation(len(V))
    new = np.empty_like(perm)
    new[perm] = np.arange(len(V))
    F2 = new[F][rng.permutation(len(F))]
    roll = rng.integers(0, 3, len(F2))
    F2 = np.take_along_axis(F2, (np.arange(3)[None, :] + roll[:, None]) % 3, axis=1)
    relabelled, X = run_mesh(scheme, V[perm], F2, tau_edge)
    named(relabelled)
    agree(relabelled, X[new], ref, ref_X, atol)
    # scaled by 1e-6 .. 1e6 (tau = c h^2 scales as the square)
    scaled, X = run_mesh(scheme, scale * V, F, tau_edge)
    named(scaled)
    agree(scaled, X / scale, ref, ref_X, atol)


CORRUPTIONS = {
    "repeated vertex": lambda V, F, i: (V, np.vstack([F, [F[i, 0], F[i, 0], F[i, 1]]])),
    "duplicate triangle": lambda V, F, i: (V, np.vstack([F, F[i][[1, 2, 0]]])),
    "zero-area triangle": lambda V, F, i: (           # a collinear triangle of its own
        np.vstack([V, V[F[i, 0]] + [5.0, 0.0, 0.0], V[F[i, 0]] + [6.0, 0.0, 0.0],
                   V[F[i, 0]] + [7.0, 0.0, 0.0]]),
        np.vstack([F, [len(V), len(V) + 1, len(V) + 2]])),
    "non-manifold edge": lambda V, F, i: (
        np.vstack([V, 3.0 * V[F[i]].mean(axis=0)]), np.vstack([F, [F[i, 1], F[i, 0],
                                                                   len(V)]])),
    "inconsistent orientation": lambda V, F, i: (V, np.vstack([F[:i], F[i, ::-1], F[i + 1:]])),
    "index out of range": lambda V, F, i: (V, np.vstack([F[:i], [F[i, 0], F[i, 1], len(V)],
                                                         F[i + 1:]])),
    "non-finite coordinate": lambda V, F, i: (np.where(np.arange(len(V))[:, None] == F[i, 0],
                                                       np.nan, V), F),
}
"""Kind of :class:`MeshError` -> a corruption of a valid mesh at its triangle ``i``."""


@pytest.mark.parametrize("kind", sorted(CORRUPTIONS))
@given(mesh=closed_meshes(), data=st.data(), scheme=st.sampled_from(sorted(SCHEMES)))
def test_invalid_meshes_are_refused_naming_the_defect(kind, mesh, data, scheme):
    V, F = mesh
    i = data.draw(st.integers(0, len(F) - 1), label="triangle")
    bad_V, bad_F = CORRUPTIONS[kind](V, F, i)
    with pytest.raises(MeshError) as err:
        run_mesh(scheme, bad_V, bad_F, 0.1)
    assert err.value.kind == kind, (err.value.kind, str(err.value))
    assert str(err.value) and str(err.value)[0].isalpha()
