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
from mcfbench.geometry.mesh_surgery import (
    NECK_RESOLUTION, curvature, cut_neck, find_neck, pinched)
from mcfbench.geometry.reextraction import SHARPNESS, open_surface, sharpness
from mcfbench.geometry.remeshing import boundary_vertices, remesh, remesh_change, target_edge
from mcfbench.running.continuation import rebuilt_flow, why_not


class CutRefused(ValueError):
    """A continuation's geometry was refused (a neck whose cut does not leave two
    loops, an open mesh's re-extraction): in ``NAME+surgery``'s run the scheme goes on
    without it (:class:`Surgeon`'s ``strict``), the refusal an event."""


def refusal(hook, flow, err):
    """``(None, the "refused" event)`` the first time ``hook`` refuses a continuation
    in a run, None afterwards (the same neck is refused at every step)."""
    if hook.refused:
        return None
    hook.refused = True
    return None, {"event": "refused", "step": flow.n, "time": flow.n * flow.tau,
                  "by": type(hook).__name__, "why": str(err)}


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


class StateCurvature:
    """The :func:`~mcfbench.geometry.mesh_surgery.curvature` and the neck
    (:func:`~mcfbench.geometry.mesh_surgery.find_neck`) of a flow's current state,
    each computed once per state and shared by ``NAME+surgery``'s hooks: the neck cut
    (:class:`Surgeon`), the re-extraction's sharpness (:class:`Reextractor`) and the
    remesh's wait (:class:`NeckWait`) ask about the same state at every step, which
    took libigl's cotangent Laplacian and Voronoi mass three times a step. A state is
    its vertices and faces, compared by value (DDFV's vertices are a new array at each
    call; a rolled back or operated flow is a new state).
    """

    def __init__(self):
        self.mesh, self.known, self.neck_of = None, None, None

    def _state(self, V, F):
        """``(V, F)`` as arrays; what was known of another state forgotten."""
        V, F = np.asarray(V, dtype=float), np.asarray(F, dtype=np.int64)
        if self.mesh is None or not (np.array_equal(V, self.mesh[0])
                                     and np.array_equal(F, self.mesh[1])):
            self.mesh, self.known, self.neck_of = (V.copy(), F.copy()), None, None
        return V, F

    def curvature(self, V, F):
        """The state's :class:`~mcfbench.geometry.mesh_surgery.Curvature`."""
        V, F = self._state(V, F)
        if self.known is None:
            self.known = curvature(V, F)
        return self.known

    def neck(self, V, F):
        """The state's neck (a :class:`~mcfbench.geometry.mesh_surgery.Neck` or None)."""
        V, F = self._state(V, F)
        if self.neck_of is None:             # a 1-tuple: a state without a neck is known
            self.neck_of = (find_neck(V, F, self.curvature(V, F)),)
        return self.neck_of[0]


def neck_surgery(scheme, flow, *, h, integrator=None, threads=1, state=None, **options):
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
    state : StateCurvature, optional
        The neck shared with the run's other hooks (default: found here).

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
    neck = (state or StateCurvature()).neck(V, F)
    early = not pinched(neck, h) and pinched(neck, h, ESCAPED_RESOLUTION)
    escaped = escaped_t_vertices(flow) if early else None      # asked near a pinch only
    early = early and len(escaped) > 0
    if not (pinched(neck, h) or early):
        return None
    where = (f"the neck at {np.round(V[neck.vertex], 4).tolist()} (radius "
             f"{neck.radius:.3g} < {NECK_RESOLUTION:g} h = {NECK_RESOLUTION * h:.3g})")
    reason = why_not(scheme, integrator)
    cut, refused = (None, None) if reason else cut_neck(V, F, neck)
    if early and (reason or refused or cut.keep_faces[escaped].any()):
        return None           # not all in the neck's thin part: the state's checks say so
    if reason:
        raise ValueError(f"{where}: {reason}")
    if refused:
        raise CutRefused(f"{where}: {refused}")
    options = {k: v for k, v in options.items() if k != "T0"}
    return cut, rebuilt_flow(scheme, flow, cut.vertices, cut.faces, threads=threads,
                             **options)


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
    strict : bool
        A refused cut (:class:`CutRefused`) ends the run (True) or the run goes on
        without it, the first refusal an event (False: ``NAME+surgery``'s
        :class:`mcfbench.running.remeshing.Strategies`, where the re-extraction may
        still take the thin part).
    state : StateCurvature, optional
        Shared with the run's other hooks (default: its own).

    Attributes
    ----------
    before_checks : bool
        True: the driver asks before a state's checks.
    kept : None or tuple of ((n,) bool array, (m,) bool array)
        The previous flow's points and triangles the last cut kept.
    """

    before_checks = True

    def __init__(self, scheme, mesh, *, integrator=None, threads=1, options=None,
                 strict=True, state=None):
        self.scheme, self.integrator, self.threads = scheme, integrator, threads
        self.state = state or StateCurvature()
        self.options = dict(options or {})
        self.h = metrics.mean_edge_length(*mesh)
        self.initial_area = metrics.area(*mesh)
        self.kept = None
        self.strict, self.refused = strict, False

    def __call__(self, flow):
        """None while no neck has pinched, else the flow rebuilt on the operated mesh
        and the ``"surgery"`` event (:class:`mcfbench.running.trajectory.Trajectory`'s
        ``events``); ``(None, "refused" event)`` the first time a cut is refused when
        not ``strict``. The event: ``{"event": "surgery", "step", "time", "where",
        "neck_radius", "pinch_time", "why", "components_before", "components_after",
        "area_removed", "volume_removed", "band_area", "area_share"}``: ``where`` the
        neck's point on its axis, ``pinch_time`` the state's time plus ``r^2 / 2`` (a
        neck of radius ``r`` shrinks as a cylinder, ``r r' = -1``), ``area_share`` the
        area removed over the initial area.

        Raises
        ------
        ValueError
            A neck pinched that cannot be cut, or a scheme that cannot be rebuilt
            (:func:`neck_surgery`).
        """
        try:
            done = neck_surgery(self.scheme, flow, h=self.h, integrator=self.integrator,
                                threads=self.threads, state=self.state, **self.options)
        except CutRefused as err:
            if not self.strict:
                return refusal(self, flow, err)
            raise ValueError(f"a neck pinched and the run cannot go on: {err}") from None
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


class Reextractor:
    """The thin parts' continuation of ``NAME+surgery``: ``reextractor(flow) -> (new
    flow, event)`` or None, asked after a state passed its checks.

    Once the surface's sharpness ``max H h`` exceeds
    :data:`~mcfbench.geometry.reextraction.SHARPNESS` (a part about to fold within a
    step), or a neck has pinched that :class:`Surgeon` did not cut (a handle's), the
    surface is re-extracted without its parts thinner than the mesh near those
    vertices (:func:`mcfbench.geometry.reextraction.open_surface`), remeshed to the
    run's edge (the ``remesh`` strategy's
    :func:`~mcfbench.geometry.remeshing.remesh`) and the scheme's flow rebuilt there
    (:func:`mcfbench.running.continuation.rebuilt_flow`'s carry-over); at most once
    per step (a thin part's cut stump may trigger it again at the next). Not on an
    open mesh (its inside is not defined): its run goes on as the scheme's own; a
    re-extraction refused (the whole surface thinner than the opening: the flow's to
    take to its extinction; marching cubes' failure, too large a grid) is a
    ``"refused"`` event, the first time, and the run goes on without it, not asked
    again until its mesh changes.

    Parameters
    ----------
    scheme, mesh, integrator, threads, options, state
        As :class:`Surgeon`'s.

    Attributes
    ----------
    before_checks : bool
        False: the re-extraction follows a valid state.
    kept : None
        The frames after it carry their own faces.
    """

    before_checks = False
    kept = None

    def __init__(self, scheme, mesh, *, integrator=None, threads=1, options=None, state=None):
        self.scheme, self.integrator, self.threads = scheme, integrator, threads
        self.state = state or StateCurvature()
        self.options = {k: v for k, v in dict(options or {}).items() if k != "T0"}
        self.h = metrics.mean_edge_length(*mesh)
        self.edge = target_edge(*mesh)
        self.initial_area = metrics.area(*mesh)
        self.last_step, self.refused, self.unchanged = None, False, None
        self.open = bool(len(boundary_vertices(mesh[1])))

    def __call__(self, flow):
        """None while the surface is not sharper than the criterion, else the flow on
        the re-extracted surface and the ``"reextracted"`` event.

        Raises
        ------
        ValueError
            The scheme cannot be rebuilt (:func:`~mcfbench.running.continuation.why_not`).
        """
        V, F = np.asarray(flow.vertices), np.asarray(flow.faces)
        if self.open or flow.n == self.last_step or len(V) == self.unchanged:
            return None
        sharp, v = sharpness(V, F, self.h, self.state.curvature(V, F))
        neck = self.state.neck(V, F)
        necks = V[neck.ring] if pinched(neck, self.h) else ()   # a neck the cut refused
        if sharp <= SHARPNESS and not len(necks):
            return None
        t = flow.n * flow.tau
        where = (f"at {np.round(V[v], 4).tolist()} (max H h = {sharp:.3g} > {SHARPNESS:g})"
                 if sharp > SHARPNESS else f"at the uncut neck at "
                 f"{np.round(V[neck.vertex], 4).tolist()} (radius {neck.radius:.3g})")
        reason = why_not(self.scheme, self.integrator)
        if reason:
            raise ValueError(f"a thin part is about to fold {where} and the run cannot go "
                             f"on: {reason}")
        opened, reason = open_surface(V, F, self.h, necks=necks)
        if reason:
            self.unchanged = len(V)          # not asked again until the mesh changes
            return refusal(self, flow, CutRefused(
                f"a thin part is about to fold {where}; not re-extracted: {reason}"))
        self.last_step = flow.n
        event = {"event": "reextracted", "step": flow.n, "time": t,
                 "where": [float(x) for x in opened.where], "sharpness": opened.sharpness,
                 "components_before": opened.components_before,
                 "components_after": opened.components_after,
                 "area_removed": opened.area_removed,
                 "volume_removed": opened.volume_removed,
                 "area_share": opened.area_removed / self.initial_area}
        U, G = remesh(opened.vertices, opened.faces, self.edge)
        event.update(remesh_change((V, F), (U, G)))
        return rebuilt_flow(self.scheme, flow, U, G, threads=self.threads,
                            **self.options), event


WAIT = 1.0
"""``NAME+surgery``'s remesh waits while a neck's radius is below this many ``h``."""


class NeckWait:
    """``NAME+surgery``'s remesh (:class:`mcfbench.running.remeshing.Remesher`), not
    while a neck's radius is below :data:`WAIT` ``h``: a neck whose circumference holds
    fewer than about six edges of the run's length is not remeshed but cut (remeshed
    there, the dumbbell's neck at level 1 lost its shape at step 26, the cut's criterion
    never held and the run ended ``inverted`` at step 30).

    Parameters
    ----------
    remesher : mcfbench.running.remeshing.Remesher
    h : float
        The run's resolution.
    state : StateCurvature, optional
        Shared with the run's other hooks (default: its own).
    """

    before_checks = False
    kept = None

    def __init__(self, remesher, h, state=None):
        self.remesher, self.h = remesher, h
        self.state = state or StateCurvature()

    def __call__(self, flow):
        neck = self.state.neck(flow.vertices, flow.faces)
        if pinched(neck, self.h, WAIT):
            return None
        return self.remesher(flow)
