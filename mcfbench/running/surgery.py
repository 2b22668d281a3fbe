"""The ``surgery`` mesh strategy (``NAME+surgery``): the driver's hook that cuts a
pinched neck and goes on with the flow rebuilt on the operated mesh.

:class:`Surgeon` is the hook of :data:`mcfbench.running.remeshing.STRATEGIES`'s
``"surgery"``, built by :func:`mcfbench.running.remeshing.mesh_hook` as the
``remesh`` strategy's :class:`~mcfbench.running.remeshing.Remesher` is, and applied
by the driver (:func:`mcfbench.running.driver.simulate`, its ``remesh``) the same
way: ``hook(flow) -> None or (new flow, event)``. Two attributes say where the two
differ: ``before_checks`` (a pinched neck is cut before the state's checks, which a
neck about to fold might fail; a remesh follows a state that passed them) and
``kept`` (the old points and triangles the new flow keeps, in order, so that the
frames keep the initial mesh's layout; None for a remesh, whose frames carry their
own faces). What is cut and how the flow is rebuilt:
:mod:`mcfbench.running.continuation`'s docstring and :func:`neck_surgery`.

A module of its own (not :mod:`~mcfbench.running.continuation`, which every run
imports) so that only a ``NAME+surgery`` run's code identity holds
:mod:`mcfbench.geometry.mesh_surgery` (:mod:`mcfbench.running.identity`).
"""

import numpy as np

from mcfbench.geometry import metrics
from mcfbench.geometry.mesh_surgery import NECK_RESOLUTION, cut_neck, find_neck, pinched
from mcfbench.running.continuation import why_not


ESCAPED_RESOLUTION = 2.0
"""A neck below this many times the resolution ``h`` is cut before it is below ``h / 2``
when DDFV's T-vertices have left their triangles there, all of them in the triangles the
cut removes (:func:`neck_surgery`): the uncarried variants' T-vertices leave the neck's
triangles when its radius is 0.9 h (level 1) to 1.4 h (level 2), before the cut
(``mcfbench/README.md``)."""


def escaped_t_vertices(flow):
    """The triangles whose T-vertex's projection has left them (a negative barycentric
    coordinate, DDFV's ``t_escaped``; Section 2.2.2), an empty array for a flow without
    T-vertices.

    Returns
    -------
    (k,) int array
    """
    barycentric = getattr(flow, "barycentric", None)
    if barycentric is None:
        return np.zeros(0, int)
    return np.flatnonzero(~(np.asarray(barycentric).min(axis=1) >= 0.0))


def neck_surgery(scheme, flow, *, h, integrator=None, threads=1, **options):
    """The cut of a ``NAME+surgery`` run (:class:`Surgeon`'s): None while no neck of
    ``flow``'s mesh has pinched (below ``h / 2``, or below :data:`ESCAPED_RESOLUTION`
    ``h`` with T-vertices out of their triangles in the part the cut removes and
    nowhere else), else the cut and the flow of ``scheme`` rebuilt on the operated mesh
    at the same time level (module docstring).

    Parameters
    ----------
    scheme : mcfbench.running.schemes.Scheme
    flow : mcfbench.running.flow.SchemeFlow
    h : float
        The run's resolution (its initial mesh's mean edge length).
    integrator, threads, **options
        As :func:`sub_flow`'s.

    Returns
    -------
    None or (mcfbench.geometry.mesh_surgery.Surgery, mcfbench.running.flow.SchemeFlow)

    Raises
    ------
    ValueError
        A neck pinched but the cut was refused (the reason), or the scheme cannot be
        rebuilt (:func:`~mcfbench.running.continuation.why_not`).
    """
    V, F = np.asarray(flow.vertices), np.asarray(flow.faces)
    neck = find_neck(V, F)
    early = not pinched(neck, h) and pinched(neck, h, ESCAPED_RESOLUTION)
    escaped = escaped_t_vertices(flow) if early else None      # asked near a pinch only
    early = early and len(escaped) > 0
    if not (pinched(neck, h) or early):
        return None
    reason = why_not(scheme, integrator)
    if reason is None:
        cut, reason = cut_neck(V, F, neck)
    if early and (reason or cut.keep_faces[escaped].any()):
        return None           # not all in the neck's thin part: the state's checks say so
    if reason:
        raise ValueError(f"the neck at {np.round(V[neck.vertex], 4).tolist()} (radius "
                         f"{neck.radius:.3g} < {NECK_RESOLUTION:g} h = "
                         f"{NECK_RESOLUTION * h:.3g}): {reason}")
    options = {k: v for k, v in options.items() if k != "T0"}
    new = scheme.make(cut.vertices, cut.faces, flow.tau, threads=threads, **options)
    new.n = flow.n
    return cut, new


class Surgeon:
    """The ``surgery`` strategy: ``surgeon(flow) -> (new flow, event)`` or None.

    Parameters
    ----------
    scheme : mcfbench.running.schemes.Scheme
    mesh : tuple of ((n, 3) float array, (m, 3) int array)
        The run's input mesh: its mean edge length is the resolution ``h`` below
        which (halved) a neck has pinched, its area the one the cuts' shares are of.
    integrator : str, optional
        The run's integrator (default the scheme's): one with past states cannot go
        on (:func:`~mcfbench.running.continuation.why_not`).
    threads : int
    options : dict
        The run's options of the flow class.

    Attributes
    ----------
    before_checks : bool
        True: the driver asks before a state's checks.
    kept : None or tuple of ((n,) bool array, (m,) bool array)
        The previous flow's points and triangles the last cut kept.
    """

    before_checks = True

    def __init__(self, scheme, mesh, *, integrator=None, threads=1, options=None):
        self.scheme, self.integrator, self.threads = scheme, integrator, threads
        self.options = dict(options or {})
        self.h = metrics.mean_edge_length(*mesh)
        self.initial_area = metrics.area(*mesh)
        self.kept = None

    def __call__(self, flow):
        """None while no neck has pinched, else the flow rebuilt on the operated mesh
        and the ``"surgery"`` event (:class:`mcfbench.running.driver.Trajectory`'s
        ``events``).

        Raises
        ------
        ValueError
            A neck pinched that cannot be cut, or a scheme that cannot be rebuilt
            (:func:`neck_surgery`).
        """
        try:
            done = neck_surgery(self.scheme, flow, h=self.h, integrator=self.integrator,
                                threads=self.threads, **self.options)
        except ValueError as err:
            raise ValueError(f"a neck pinched and the run cannot go on: {err}") from None
        if done is None:
            return None
        cut, new = done
        t = flow.n * flow.tau
        self.kept = (cut.keep_vertices, cut.keep_faces)
        return new, {
            "event": "surgery", "step": flow.n, "time": t,
            "where": [float(x) for x in cut.where], "neck_radius": cut.radius,
            "pinch_time": t + cut.radius ** 2 / 2.0,
            "why": (f"neck radius below {NECK_RESOLUTION:g} h" if cut.radius < NECK_RESOLUTION
                    * self.h else f"T-vertices out of their triangles in the neck (radius "
                    f"below {ESCAPED_RESOLUTION:g} h)"),
            "components_before": cut.components_before,
            "components_after": cut.components_after, "area_removed": cut.area_removed,
            "volume_removed": cut.volume_removed, "band_area": cut.band_area,
            "area_share": cut.area_removed / self.initial_area}
