"""The registry of problems: initial surface, refinement series, time rule, metrics.

A problem is one entry of :data:`PROBLEMS`: a surface generator of
:mod:`mcfbench.geometry.surfaces` with its parameters per refinement level, the time
step of each level, the final time, an optional steady-state threshold and
the metrics (observers of :mod:`mcfbench.geometry.metrics` and
:mod:`mcfbench.geometry.exact`) measured on every run. Table 3.1 of the paper is
the problem ``sphere`` run by the scheme ``ddfv``.

A new problem is one entry here (and, if it needs one, a generator in
:mod:`mcfbench.geometry.surfaces` or a metric in :mod:`mcfbench.geometry.metrics`).
"""

import math
from dataclasses import dataclass, field, replace

from mcfbench.geometry import metrics as _metrics
from mcfbench.geometry.exact import SphereL2Error


@dataclass(frozen=True)
class Problem:
    """One benchmark problem.

    Attributes
    ----------
    name, label : str
    surface : str
        A name of :data:`mcfbench.geometry.surfaces.SURFACES`.
    params : callable
        ``params(level) -> dict`` of the generator's keyword arguments.
    levels : tuple of int
        The default refinement series (each level halves the mesh size).
    tau_1 : float
        Time step of level 1; level ``k`` uses ``tau_1 / 4**(k - 1)``
        (``tau ~ h^2``), unless ``tau_rule`` is ``"mesh"``.
    t_final : float
        Final time (a whole multiple of every level's time step when
        ``tau_rule`` is ``"level"``).
    metrics : tuple of str
        Names of :data:`METRICS` measured on every run.
    steady_speed : float or None
        Stop when the largest vertex speed falls below this (the steady
        state of the catenoid and the flat disk).
    tau_rule : {"level", "mesh"}
        ``"mesh"``: ``tau = tau_1 * (mean edge length)^2`` and ``steps``
        steps (meshes without a refinement series).
    steps : int or None
        Number of steps for ``tau_rule = "mesh"``.
    exact : str
        What the exact (or reference) answer is, for tables and the report.
    t_max : float or None
        Runs must end before this time (the sphere's extinction ``R^2/4``).
    """

    name: str
    label: str
    surface: str
    params: object
    levels: tuple
    tau_1: float
    t_final: float
    metrics: tuple
    steady_speed: float | None = None
    tau_rule: str = "level"
    steps: int | None = None
    exact: str = ""
    t_max: float | None = None
    description: str = field(default="", compare=False)

    def mesh(self, level):
        """``(vertices, faces)`` of refinement ``level``."""
        from mcfbench.geometry.surfaces import make_surface  # scipy: on first use

        return make_surface(self.surface, **self.params(int(level)))

    def tau(self, level, mesh=None):
        """Time step of ``level`` (``mesh`` needed for the ``"mesh"`` rule)."""
        if self.tau_rule == "mesh":
            V, F = self.mesh(level) if mesh is None else mesh
            return self.tau_1 * _metrics.mean_edge_length(V, F) ** 2
        return self.tau_1 / 4.0 ** (int(level) - 1)

    def time_steps(self, tau, t_final=None):
        """Number of steps ``N`` of a run with time step ``tau``.

        Raises
        ------
        ValueError
            ``t_final`` not a whole multiple of ``tau``, or not before ``t_max``.
        """
        if self.tau_rule == "mesh" and t_final is None:
            return int(self.steps)
        t_final = self.t_final if t_final is None else t_final
        steps = time_steps(t_final, tau)
        if self.t_max is not None and steps * tau >= self.t_max:
            raise ValueError(f"t_final = {steps * tau:g} is past the extinction time "
                             f"{self.t_max:g} of the {self.name} ({self.exact})")
        return steps

    @classmethod
    def user_mesh(cls, label, steps, tau_edge=0.1):
        """The problem of a user's mesh: ``tau = tau_edge h^2``, ``steps`` steps, no
        exact answer (the mesh is passed to :func:`mcfbench.running.run.run`)."""
        return cls("user", label, "", lambda level: {}, levels=(0,), tau_1=tau_edge,
                   t_final=0.0, metrics=(), tau_rule="mesh", steps=int(steps),
                   exact="no exact solution: a user's mesh")

    def observers(self):
        """Fresh metric observers for one run."""
        return [METRICS[name](self) for name in self.metrics]

    def with_settings(self, **settings):
        """A copy with fields replaced (``tau_1``, ``t_final``, ``levels``, ...)."""
        return replace(self, **settings)


def time_steps(t_final, tau):
    """Number of steps ``N = t_final / tau``; ``t_final`` must be a whole multiple of ``tau``.

    Raises
    ------
    ValueError
        Naming both values.
    """
    if not (math.isfinite(tau) and tau > 0):
        raise ValueError(f"tau must be a positive number, got {tau!r}")
    if not (math.isfinite(t_final) and t_final > 0):
        raise ValueError(f"t_final must be a positive number, got {t_final!r}")
    steps = round(t_final / tau)
    if steps < 1 or not math.isclose(steps * tau, t_final, rel_tol=1e-12):
        raise ValueError(f"t_final = {t_final} is not a whole multiple of tau = {tau} "
                         f"(t_final / tau = {t_final / tau:g})")
    return steps


class _Final:
    """Observer base: keeps the last state it saw and reports a dict at the end."""

    def __init__(self, problem):
        self.problem = problem
        self.V = self.faces = self.fixed = None
        self.t = 0.0

    def __call__(self, flow):
        self.V, self.faces, self.t = flow.vertices, flow.faces, flow.n * flow.tau
        self.fixed = getattr(flow, "fixed", None)

    def result(self):
        raise NotImplementedError


class _SphereError(SphereL2Error):
    """The error (3.2) against ``r(t) = sqrt(R^2 - 4t)``: ``{"l2_error": ...}``."""

    def __init__(self, problem):
        super().__init__(problem.params(1).get("radius", 1.0))

    def result(self):
        return {"l2_error": self.value}


class _Catenoid(_Final):
    """Neck and profile error against ``a cosh(z/a)`` at the final state."""

    def result(self):
        params = self.problem.params(1)
        a = _metrics.catenoid_parameter(params["radius"], params["half_height"])
        return _metrics.catenoid_profile_error(self.V, a, self.fixed)


class _Height(_Final):
    """Distance of the final surface from the flat disk ``z = 0``."""

    def result(self):
        return {"max_height": _metrics.max_height(self.V),
                "l2_height": _metrics.l2_height(self.V, self.faces)}


class _Shape(_Final):
    """Volume and area of the final state."""

    def result(self):
        return {"volume": _metrics.volume(self.V, self.faces),
                "area": _metrics.area(self.V, self.faces)}


class _Still(_Final):
    """Largest displacement of a vertex from its initial position (flat patch)."""

    def __call__(self, flow):
        if self.V is None:
            self.V0 = flow.vertices.copy()
        super().__call__(flow)

    def result(self):
        import numpy as np

        return {"max_displacement": float(np.linalg.norm(self.V - self.V0, axis=1).max()),
                "max_height": _metrics.max_height(self.V)}


METRICS = {"sphere_l2": _SphereError, "catenoid": _Catenoid, "height": _Height,
           "shape": _Shape, "still": _Still}
"""Metric name -> observer class (called with the problem)."""


def _sphere_params(level):
    return {"level": int(level), "radius": 1.0}


PROBLEMS = {p.name: p for p in (
    Problem("sphere", "shrinking sphere (Table 3.1)", "sphere", _sphere_params,
            levels=(1, 2, 3, 4, 5), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
            exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
            description="The unit icosphere of Section 3.1, tau = 0.04 / 4^(k-1), t_f = 0.08; "
                        "the error (3.2)."),
    Problem("catenoid", "cylinder to catenoid", "cylinder",
            lambda level: {"around": 24 * 2 ** (level - 1), "along": 8 * 2 ** (level - 1),
                           "radius": 1.0, "half_height": 0.5},
            levels=(1, 2, 3, 4), tau_1=0.004, t_final=1.5, metrics=("catenoid",),
            steady_speed=1e-6, exact="r(z) = a cosh(z/a), a cosh(0.5/a) = 1, a = 0.848338",
            description="An open cylinder of radius 1 between z = -0.5 and 0.5, boundary "
                        "circles fixed, alternating diagonals, tau = 0.001 (16/n_z)^2, run to "
                        "the steady state."),
    Problem("hemisphere", "hemisphere to flat disk", "hemisphere",
            lambda level: {"rings": 5 * 2 ** (level - 1), "radius": 1.0},
            levels=(1, 2, 3, 4), tau_1=0.01, t_final=2.0, metrics=("height",),
            steady_speed=1e-6, exact="the flat disk z = 0",
            description="The unit hemisphere with its equator fixed flows to the disk."),
    Problem("torus", "torus (2, 0.5) pinching", "torus",
            lambda level: {"R": 2.0, "r": 0.5, "n_major": 32 * 2 ** (level - 1),
                           "n_minor": 8 * 2 ** (level - 1)},
            levels=(1, 2, 3), tau_1=0.004, t_final=0.2, metrics=("shape",),
            exact="no exact solution: the tube shrinks and pinches (t about 0.12)",
            description="A torus of radii 2 and 0.5; volume and area against the finest "
                        "level of the same scheme, breakdown time and mesh quality."),
    Problem("dumbbell", "dumbbell pinch-off", "dumbbell",
            lambda level: {"level": int(level)},
            levels=(1, 2, 3), tau_1=0.004, t_final=0.2, metrics=("shape",),
            exact="no exact solution: the neck pinches before the bulbs vanish",
            description="Two spheres joined by a thin neck: when each scheme breaks down or "
                        "the neck pinches, and the mesh quality before it."),
    # real-world-like meshes the suite generates itself (issue: every scheme runs a
    # scanned or CAD-like mesh or says precisely why not)
    Problem("perturbed_sphere", "sphere, randomly perturbed mesh", "perturbed_sphere",
            lambda level: {"level": int(level), "amplitude": 0.25, "seed": 0},
            levels=(1, 2, 3, 4), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
            exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
            description="The icosphere with vertices moved at random along the sphere: "
                        "irregular valences and angles, exact solution known."),
    Problem("remeshed_sphere", "sphere, random convex-hull mesh", "remeshed_sphere",
            lambda level: {"n_points": 10 * 4 ** int(level) + 2, "seed": 0},
            levels=(1, 2, 3, 4), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
            exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
            description="Random points on the unit sphere triangulated by their convex hull "
                        "(slivers, valences 3 to 10)."),
    Problem("anisotropic_sphere", "sphere, anisotropic UV mesh", "anisotropic_sphere",
            lambda level: {"level": int(level), "stretch": 4.0},
            levels=(1, 2, 3, 4), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
            exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
            description="A UV sphere with long thin triangles (length/width 4 at the "
                        "equator) and poles of high valence."),
    Problem("flat_patch", "flat patch stays flat and still", "flat_patch",
            lambda level: {"level": int(level), "jitter": 0.3, "seed": 0},
            levels=(1, 2, 3), tau_1=0.01, t_final=0.2, metrics=("still",),
            exact="no motion: the flat disk is its own steady state",
            description="An irregular Delaunay mesh of the unit disk with its boundary fixed: "
                        "every vertex must stay where it is."),
    Problem("blobby", "marching-cubes blob (genus 0)", "blobby",
            lambda level: {"resolution": 20 * 2 ** int(level)},
            levels=(1,), tau_1=0.1, t_final=0.0, metrics=("shape",), tau_rule="mesh", steps=40,
            exact="no exact solution: smoothing of a scanned-like mesh",
            description="Marching cubes of a sum of metaballs: irregular valences and slivers "
                        "as in scanned meshes; tau = 0.1 h^2, 40 steps."),
    Problem("marching_torus", "marching-cubes torus (genus 1)", "implicit_torus",
            lambda level: {"resolution": 24 * 2 ** int(level)},
            levels=(1,), tau_1=0.1, t_final=0.0, metrics=("shape",), tau_rule="mesh", steps=40,
            exact="no exact solution: smoothing of a scanned-like mesh",
            description="Marching cubes of a tilted torus (genus 1); tau = 0.1 h^2, 40 steps."),
)}
"""Problem name -> :class:`Problem`."""


def get_problem(name):
    """The registry entry ``name``.

    Raises
    ------
    ValueError
        Unknown name, listing the known ones.
    """
    try:
        return PROBLEMS[name]
    except KeyError:
        raise ValueError(f"unknown problem {name!r}; choose one of "
                         f"{', '.join(PROBLEMS)}") from None
