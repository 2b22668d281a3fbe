"""Shared meshes for the tests: the generators of :mod:`mcfbench.geometry.surfaces`."""

import functools
import os
from dataclasses import dataclass, field, replace

import numpy as np
import pytest
from hypothesis import HealthCheck, settings
from scipy.spatial import ConvexHull

from mcfbench.geometry import surfaces
from mcfbench.geometry.shapes import flat_lattice
from mcfbench.geometry.spheres import icosphere
from mcfbench.geometry.spheres import random_bumpy_sphere as bumpy_sphere
from mcfbench.running.solver import Solver

# The tests that import ``cylinder`` from here were written for quads all cut
# along the same diagonal; the positional parameters (around, along, radius,
# half_height = 0.5) are those of mcfbench.geometry.shapes.cylinder.
cylinder = functools.partial(surfaces.cylinder, diagonals="parallel")

__all__ = ["FailsAt", "approaches_the_catenoid", "bumpy_sphere", "cylinder", "flat_lattice",
           "table_3_1_error", "twin_sphere"]

# hypothesis (tests/mcfbench/running/test_run_properties.py): "ci", the default, draws the same few
# examples on every run (derandomized, no example database); HYPOTHESIS_PROFILE=nightly
# draws fresh ones, 25 times as many.
settings.register_profile("ci", max_examples=10, derandomize=True, database=None, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow], print_blob=True)
settings.register_profile("nightly", max_examples=100, deadline=None,
                          suppress_health_check=[HealthCheck.too_slow], print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


@pytest.fixture
def bumpy():
    return bumpy_sphere()


@pytest.fixture
def split_cube_file(tmp_path):
    """A cube split twice (192 triangles) written to ``tmp_path / "cube.obj"``: the
    paper's DDFV loses a T-vertex on it within 60 steps of tau = 0.01."""
    import igl

    from mcfbench.geometry.spheres import subdivide

    V = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    F = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                  [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    for _ in range(2):
        V, F = subdivide(V, F)
    mesh = tmp_path / "cube.obj"
    igl.write_triangle_mesh(str(mesh), V, F)
    return mesh


@pytest.fixture(scope="module")
def timed_once():
    """``mcfbench.running.run.run`` executes each run's timed part once, for a module
    (``pytestmark = pytest.mark.usefixtures("timed_once")``) whose tests check what a
    run computes, not its time. A run's result is that of its first execution; a run
    under ``SHORT_RUN`` CPU seconds (most runs of the tests) is otherwise executed
    again for its time, up to ``MAX_REPEATS`` times in about ``REPEAT_BUDGET`` CPU
    seconds (0.2 s a run; tested in ``tests/mcfbench/running/test_run.py``)."""
    from mcfbench.running import run

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(run, "MAX_REPEATS", 1)
        yield


@pytest.fixture(scope="module")
def noisy_sphere():
    """A level-2 icosphere with radial noise: no symmetry hides index errors."""
    V, F = icosphere(2)
    rng = np.random.default_rng(7)
    return V * (1.0 + 0.1 * rng.random((len(V), 1))), F


def approaches_the_catenoid(X, tol=0.004):
    """Frames ``X`` (frames, n, 3) of the 24 x 8 cylinder (R = 1, h = 0.5): the neck
    shrinks monotonically to ``a = 0.84834`` (1 %) and the last profile is
    ``a cosh(z / a)`` to ``tol``."""
    from mcfbench.geometry.metrics import catenoid_parameter

    a = catenoid_parameter(1.0, 0.5)
    r, z = np.hypot(X[..., 0], X[..., 1]), X[..., 2]
    neck = np.array([r[k][np.abs(z[k]) < 0.07].mean() for k in range(len(X))])
    assert np.all(np.diff(neck) < 0), neck
    assert neck[-1] == pytest.approx(a, rel=0.01)
    np.testing.assert_allclose(r[-1], a * np.cosh(z[-1] / a), atol=tol)


def table_3_1_error(flow, level, solver=None):
    """The setting of the paper's Table 3.1: ``flow(V, F, tau)`` from the icosphere of
    ``level``, ``tau = 0.04 / 4**(level - 1)``, to ``t = 0.08``; the run must finish.

    Returns
    -------
    error : float
        The L2 error (3.2) against the exact radius ``sqrt(1 - 4t)``.
    trajectory : mcfbench.running.trajectory.Trajectory
    """
    from mcfbench.geometry.exact import SphereL2Error
    from mcfbench.running.driver import simulate
    from mcfbench.running.solver import Solver

    V, F = icosphere(level)
    tau = 0.04 / 4 ** (level - 1)
    error = SphereL2Error(1.0)
    traj = simulate(flow(V, F, tau), round(0.08 / tau), solver=solver or Solver(),
                    save_every=0, observers=[error])
    assert traj.status == "ok", traj.message
    return error.value, traj


def twin_sphere(n=162, eps=0.1, seed=0):
    """Sliver-rich sphere: n/2 random points each with a twin at eps x the mean
    spacing, triangulated by their convex hull (tiny triangles and slivers)."""
    rng = np.random.default_rng(seed)
    P = rng.standard_normal((n // 2, 3))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    d = rng.standard_normal((n // 2, 3))
    d -= (d * P).sum(1, keepdims=True) * P
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    P = np.vstack([P, P + eps * np.sqrt(4 * np.pi / n) * d])
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    F = ConvexHull(P).simplices.copy()
    normal = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    flip = (normal * P[F].mean(axis=1)).sum(axis=1) < 0
    F[flip] = F[flip][:, ::-1]
    return P, F


@dataclass(frozen=True)
class FailsAt(Solver):
    """The solver, but its ``at``-th solve of a system of ``size`` unknowns (the run's,
    not the warm-up's) stops after one iteration: ``solver_failed``."""

    at: int = 0
    size: int = 0
    calls: list = field(default_factory=list)

    def __call__(self, A, b, x0, **kw):
        self.calls.extend([1] if A.shape[0] == self.size else [])
        failing = replace(self, maxiter=1) if len(self.calls) == self.at else self
        return Solver.__call__(failing, A, b, x0, **kw)
