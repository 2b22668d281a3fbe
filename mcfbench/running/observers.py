"""The metric observers of the problems: what a run measures, by name.

An observer is a class called with the problem (``cls(problem)``), then with the
flow after every accepted step; ``result()`` returns ``{metric: value}``.
:attr:`mcfbench.running.problem.Problem.metrics` names them in :data:`METRICS`; a
problem module of :mod:`mcfbench.problems` (or an installed package's) adds its own
with a ``METRICS`` dict (:func:`mcfbench.running.problems.discover_problems`).
"""

import math

from mcfbench.geometry import metrics as _metrics
from mcfbench.geometry.exact import SphereL2Error, catenoid_area, disk_decay_rate


class _Final:
    """Observer base: keeps the last state it saw and reports a dict at the end."""

    def __init__(self, problem):
        self.problem = problem
        self.V = self.faces = self.fixed = self.flow = None
        self.t = 0.0

    def __call__(self, flow):
        self.V, self.t = flow.vertices, flow.n * flow.tau
        if flow is not self.flow:  # read once per flow (DDFV's fixed: a gather); a new
            # one when the run goes on without a component or through a neck's cut
            self.flow, self.faces, self.fixed = flow, flow.faces, getattr(flow, "fixed", None)

    def result(self):
        raise NotImplementedError


class _SphereError(SphereL2Error):
    """The error (3.2) against ``r(t) = sqrt(R^2 - 4t)``: ``{"l2_error": ...}``."""

    def __init__(self, problem):
        super().__init__(problem.params(1).get("radius", 1.0))

    def result(self):
        return {"l2_error": self.value}


class _Catenoid(_Final):
    """Neck and profile error against ``a cosh(z/a)`` at the final state, and the
    relative error of its area against ``pi a (2h + a sinh(2h/a))``."""

    def result(self):
        params = self.problem.params(1)
        a = _metrics.catenoid_parameter(params["radius"], params["half_height"])
        area = catenoid_area(params["radius"], params["half_height"])
        return {**_metrics.catenoid_profile_error(self.V, a, self.fixed),
                "area_error": _metrics.area(self.V, self.faces) / area - 1.0}


class _Sampled(_Final):
    """Observer base: values measured at given times before the run's end, so
    they stay valid when the run breaks down later (``keeps_before_breakdown``)."""

    keeps_before_breakdown = True
    times = ()

    def __init__(self, problem):
        super().__init__(problem)
        self.samples = {}

    def __call__(self, flow):
        super().__call__(flow)
        for t in self.times:
            if math.isclose(self.t, t, rel_tol=1e-9, abs_tol=1e-12):
                self.samples[t] = self.measure(flow)

    def sample(self, t):
        return self.samples.get(t, math.nan)


class _Decay(_Sampled):
    """The rate at which the height decays towards the flat disk, between
    ``t = 1`` and ``1.5``, against ``j_{0,1}^2 / R^2``: ``decay_rate_error``
    (relative), and the final height."""

    times = (1.0, 1.5)

    def measure(self, flow):
        return _metrics.max_height(flow.vertices)

    def result(self):
        h1, h2 = (self.sample(t) for t in self.times)
        rate = math.log(h1 / h2) / (self.times[1] - self.times[0]) if h1 > 0 and h2 > 0 \
            else math.nan
        exact = disk_decay_rate(self.problem.params(1).get("radius", 1.0))
        return {"decay_rate_error": rate / exact - 1.0,
                "max_height": _metrics.max_height(self.V)}


class _ReferenceVolume(_Sampled):
    """Relative error of the enclosed volume at ``reference["volume_time"]``
    against the axisymmetric reference (before the pinch)."""

    def __init__(self, problem):
        super().__init__(problem)
        self.times = (problem.reference["volume_time"],)

    def measure(self, flow):
        return _metrics.volume(flow.vertices, flow.faces)

    def result(self):
        return {"volume_error": self.sample(self.times[0]) / self.problem.reference["volume"]
                - 1.0}


class _BulbVolume(_Sampled):
    """Past a pinch (``NAME+surgery``), the volume of every closed component at
    ``reference["bulb_volume_times"]`` against the axisymmetric reference's one bulb
    (:mod:`mcfbench.geometry.meridian_surgery`): ``bulb_volume_error``, the relative
    error of largest size over the components and the times (a run that has not cut
    its neck by then has one component, twice a bulb's volume: an error near 1),
    NaN when a time was not reached."""

    def __init__(self, problem):
        super().__init__(problem)
        self.times = tuple(problem.reference["bulb_volume_times"])

    def measure(self, flow):
        from mcfbench.geometry.collapse import component_volumes
        from mcfbench.geometry.measures import vertex_components

        count, labels = vertex_components(flow.faces, len(flow.vertices))
        return component_volumes(flow.vertices, flow.faces, labels[flow.faces[:, 0]], count)

    def result(self):
        import numpy as np

        errors = [np.abs(np.asarray(self.samples[t]) / volume - 1.0).max()
                  if t in self.samples else math.nan
                  for t, volume in zip(self.times, self.problem.reference["bulb_volume"])]
        return {"bulb_volume_error": float(max(errors))}


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


class _Angenent(_Final):
    """The final state against the Angenent torus ``sqrt(1 - t) M_0``: the largest
    distance of a vertex to it, and the relative error of the area ``(1 - t) A_0``."""

    def result(self):
        from mcfbench.geometry.angenent import angenent_area, angenent_distance

        return {"distance_error": float(angenent_distance(self.V, self.t).max()),
                "area_error": _metrics.area(self.V, self.faces) / angenent_area(self.t) - 1.0}


class _Enneper(_Final):
    """The final state against Enneper's minimal surface: the relative error of
    the area and the largest vertical distance of a vertex to the surface."""

    def result(self):
        from mcfbench.geometry.minimal import enneper_area, enneper_height_error

        radius = self.problem.params(1)["radius"]
        return {"area_error": _metrics.area(self.V, self.faces) / enneper_area(radius) - 1.0,
                "height_error": enneper_height_error(self.V)}


class _Still(_Final):
    """Largest displacement of a vertex from its initial position (flat patch); of a
    remeshed run, the largest distance of a vertex from the initial surface."""

    def __call__(self, flow):
        if self.V is None:
            self.V0, self.F0, self.first = flow.vertices.copy(), flow.faces, flow
        super().__call__(flow)

    def result(self):
        import numpy as np

        if self.flow is self.first:
            moved = np.linalg.norm(self.V - self.V0, axis=1)
        else:       # a remeshed run's vertices are new ones: their distance to the initial
            import igl                                                  # surface

            moved = np.sqrt(igl.point_mesh_squared_distance(
                np.asarray(self.V, float), self.V0, np.asarray(self.F0, np.int64))[0])
        return {"max_displacement": float(moved.max()),
                "max_height": _metrics.max_height(self.V)}


METRICS = {"sphere_l2": _SphereError, "catenoid": _Catenoid, "height": _Height,
           "shape": _Shape, "still": _Still, "decay": _Decay,
           "reference_volume": _ReferenceVolume, "angenent": _Angenent,
           "enneper": _Enneper, "bulb_volume": _BulbVolume}
"""Metric name -> observer class (called with the problem)."""
