"""What a run (:func:`mcfbench.running.run.run`) watches at every time level: the T
monitor and the mesh quality (:class:`Monitor`), and whether the problem's steady
state is reached (:class:`Steady`)."""

import copy

import numpy as np

from mcfbench.geometry import metrics


class Monitor:
    """Observer: the T monitor at every level, mesh quality every ``every`` levels."""

    def __init__(self, every):
        self.every = max(1, int(every))
        self.t, self.t_monitor = [], []
        self.quality = {"quality_t": [], "min_angle": [], "max_aspect": [], "flipped": [],
                        "covolume_ratio": []}
        self._neighbours, self._faces = None, 0

    def __call__(self, flow):
        t = flow.n * flow.tau
        self.t.append(t)
        monitor = getattr(flow, "t_min_barycentric", None)
        self.t_monitor.append(monitor() if monitor is not None else float("nan"))
        if flow.n % self.every == 0:
            self.sample(flow)

    def finished(self, flow):
        """A copy with the last state reached included (an invalid one too, when
        finite); this monitor stays as the run left it, for a continued run
        (:func:`mcfbench.running.run.run`'s ``robust``) to go on with."""
        done = copy.copy(self)
        done.t, done.t_monitor = list(self.t), list(self.t_monitor)
        done.quality = {key: list(values) for key, values in self.quality.items()}
        if not np.isfinite(flow.X).all():
            return done
        if not done.t or done.t[-1] != flow.n * flow.tau:
            done(flow)
        done.sample(flow)
        return done

    def sample(self, flow):
        if self.quality["quality_t"] and self.quality["quality_t"][-1] == flow.n * flow.tau:
            return
        if self._neighbours is None or not np.array_equal(self._faces, flow.faces):
            # (again for the flow rebuilt on the components that remain of a run, or
            # on a new mesh)
            self._faces = np.array(flow.faces)
            self._neighbours = metrics.edge_neighbours(self._faces)
        V = flow.vertices
        q = metrics.quality(V, flow.faces, self._neighbours)
        self.quality["quality_t"].append(flow.n * flow.tau)
        self.quality["min_angle"].append(q["min_angle"])
        self.quality["max_aspect"].append(q["max_aspect_ratio"])
        self.quality["flipped"].append(q["flipped_triangles"])
        # the scheme's own covolumes (DDFV: the F-vertices' come first)
        self.quality["covolume_ratio"].append(metrics.covolume_ratio(
            np.asarray(flow.l2_weights)[:len(V)], flow.faces))


class Steady:
    """``until`` of the driver: the largest vertex speed fell below ``speed``.

    The speed is :func:`mcfbench.geometry.metrics.max_speed` of the last two
    states (one compiled pass), the previous one kept in a buffer for the run: a
    steady-state problem takes thousands of steps on a small mesh, where numpy's
    temporaries cost more than the arithmetic.
    """

    def __init__(self, speed):
        self.speed, self.previous, self.reached = speed, None, False

    def __call__(self, flow):
        V = flow.vertices
        if self.previous is None or self.previous.shape != V.shape:
            # (again for the flow rebuilt on the components that remain of a run)
            self.previous = np.array(V, dtype=float, order="F")
            self.reached = False
            return False
        largest = metrics.max_speed(self.previous, V, flow.tau)
        np.copyto(self.previous, V)
        self.reached = bool(largest < self.speed)
        return self.reached
