"""A run's mesh strategies (``NAME+remesh``, ``NAME+surgery``): the driver's hooks.

:func:`mesh_hook` builds, for a scheme whose name carries a strategy of
:data:`mcfbench.running.scheme.MESH_STRATEGIES`, its hook (:data:`STRATEGIES`), which
the driver (:func:`mcfbench.running.driver.simulate`, its ``remesh``) applies to every
state: ``hook(flow) -> None or (new flow, event)``, asked before the state's checks
when ``hook.before_checks``, else after them; the new flow's frames keep the previous
layout where ``hook.kept`` names the points and triangles kept, else carry their own
faces. The ``surgery`` strategy (:class:`Strategies`) cuts a pinched neck
(:class:`mcfbench.running.surgery.Surgeon`), re-extracts the surface without its parts
thinner than the mesh once they are about to fold
(:class:`mcfbench.running.surgery.Reextractor`) and remeshes as ``remesh`` does.
:class:`Remesher`, the ``remesh`` strategy, remeshes the
current surface when :class:`mcfbench.geometry.remeshing.RemeshTrigger` says so
(:func:`mcfbench.geometry.remeshing.remesh`: Botsch and Kobbelt's isotropic
remeshing, the target edge that keeps the input's vertex count) and rebuilds the
flow there, as the continuation after a vanished component does
(:mod:`mcfbench.running.continuation`): the scheme's own construction on the new
vertices and faces, at the same time level, the integrator restarted by the driver.
What the new flow carries over:

- the positions: the remesher's (projected onto the current surface);
- DDFV's T-vertices: re-initialised by the scheme's own placement rule
  (``t_init``), as the paper's start does (a new triangle has no old T-vertex);
- KLL's normal and mean curvature: re-initialised from the new mesh, as KLL's own
  start measures them from the initial mesh (a closest-point interpolation of the
  old values would add an interpolation error of the same ``O(h^2)`` as the
  measurement's and a second code path for one scheme);
- BDF2 and BDF3: their past states lived on the old vertices: the run restarts
  with the integrator's first step (the driver's fresh integrator), as after a
  vanished component;
- the tangential strategies that keep something of the initial state
  (``deturck``'s map onto the initial mesh, ``conformal``'s initial stiffness,
  ``redistribute``'s initial area): the remeshed surface becomes their initial one
  (:data:`mcfbench.running.continuation.STATE_ONLY` names those that lose nothing).

A step whose new state folds is rolled back, the state before it remeshed and the step
redone (:attr:`Remesher.rollback`, :mod:`mcfbench.running.rollback`; ``NAME+surgery``'s
through its remesher).
"""

from mcfbench.geometry.remeshing import (
    ANGLE, PASSES, RemeshTrigger, remesh, remesh_change, target_edge)
from mcfbench.running.continuation import rebuilt_flow
from mcfbench.running.rollback import Rollback
from mcfbench.running.scheme import parse_name
from mcfbench.running.surgery import NeckWait, Reextractor, StateCurvature, Surgeon


class Remesher:
    """The ``remesh`` strategy: ``remesher(flow) -> (new flow, event)`` or None.

    Parameters
    ----------
    scheme : mcfbench.running.schemes.Scheme
    mesh : tuple of ((n, 3) float array, (m, 3) int array)
        The run's input mesh: the target edge length's (:func:`target_edge`).
    integrator : str, optional
        The run's integrator: the strategies' common signature (:func:`mesh_hook`);
        a remesh restarts any (the driver's fresh integrator).
    threads : int
    options : dict
        The run's options of the flow class.
    angle, every : float
        The trigger's (:class:`~mcfbench.geometry.remeshing.RemeshTrigger`).
    passes : int

    Attributes
    ----------
    before_checks : bool
        False: the driver asks after a state passed its checks.
    kept : None
        A remeshed flow keeps no layout: its frames carry their own faces.
    h : float
        The target edge length.
    calls : int
    seconds : float
        Wall seconds spent remeshing and measuring the change (an event's
        ``seconds``: the remesh alone, its checks included).
    rollback : mcfbench.running.rollback.Rollback
        The driver's ``rollback`` after a step that folds (the state before the step
        remeshed by :meth:`remeshed`).
    """

    before_checks = False
    kept = None

    def __init__(self, scheme, mesh, *, integrator=None, threads=1, options=None,
                 angle=ANGLE, every=None, passes=PASSES):
        self.scheme, self.threads, self.options = scheme, threads, dict(options or {})
        self.h, self.passes = target_edge(*mesh), passes
        self.trigger = RemeshTrigger(angle, every)
        self.calls, self.seconds = 0, 0.0
        self.rollback = Rollback(self)

    def __call__(self, flow):
        V, F = flow.vertices, flow.faces
        why = self.trigger(V, F, flow.n * flow.tau)
        return None if why is None else self.remeshed(flow, V, F, flow.n, why)

    def remeshed(self, flow, V, F, n, why):
        """The flow of the surface ``(V, F)`` of time level ``n`` remeshed (``flow``'s
        scheme and time step) and the ``"remeshed"`` event saying ``why``; the trigger
        told (also for a :class:`~mcfbench.running.rollback.Rollback`'s remesh). The
        event: ``{"event": "remeshed", "step", "time", "why", "seconds", ...}``,
        ``seconds`` the remesh's wall time, then the fields of
        :func:`mcfbench.geometry.remeshing.remesh_change` (the distance between the
        surfaces before and after, the changes of area and volume, the vertex counts,
        whether the components or genus changed).

        Raises
        ------
        mcfbench.geometry.remeshing.RemeshRefused
            ``(V, F)`` or the remesh is not a valid surface.
        """
        import time

        t = n * flow.tau
        start = time.perf_counter()
        U, G = remesh(V, F, self.h, self.passes)
        seconds = time.perf_counter() - start
        event = {"event": "remeshed", "step": n, "time": t, "why": why,
                 "seconds": seconds, **remesh_change((V, F), (U, G))}
        self.seconds += time.perf_counter() - start
        self.calls += 1
        self.trigger.done(t, event["min_angle_after"])
        new = rebuilt_flow(self.scheme, flow, U, G, threads=self.threads, **self.options)
        new.n = n
        return new, event


class Strategies:
    """Several hooks as one (``NAME+surgery``'s): the driver asks its ``parts`` in
    order (:meth:`mcfbench.running.driver.Runner.remeshed`), each where its own
    ``before_checks`` says, the first that operates winning: the neck cut
    (:class:`~mcfbench.running.surgery.Surgeon`, before the checks), then the thin
    parts' re-extraction (:class:`~mcfbench.running.surgery.Reextractor`) and the
    remesh (:class:`Remesher`, waiting while a neck is near its cut:
    :class:`~mcfbench.running.surgery.NeckWait`), both after them.

    Parameters
    ----------
    scheme, mesh, integrator, threads, options
        As every hook's (:func:`mesh_hook`).
    """

    modules = ("mcfbench.running.remeshing", "mcfbench.running.surgery")
    """Its parts' modules: the roots of its runs' code identity
    (:func:`mcfbench.running.identity.scheme_roots`)."""

    def __init__(self, scheme, mesh, *, integrator=None, threads=1, options=None):
        kwargs = {"integrator": integrator, "threads": threads, "options": options}
        state = StateCurvature()             # one curvature a state for the three
        surgeon = Surgeon(scheme, mesh, strict=False, state=state, **kwargs)
        remesher = Remesher(scheme, mesh, **kwargs)
        self.parts = (surgeon, Reextractor(scheme, mesh, state=state, **kwargs),
                      NeckWait(remesher, surgeon.h, state))
        self.rollback = remesher.rollback         # the remesher's (Remesher.rollback)


STRATEGIES = {"remesh": Remesher, "surgery": Strategies}
"""A mesh strategy (a key of :data:`mcfbench.running.scheme.MESH_STRATEGIES`) -> the
class of its hook, built as ``cls(scheme, mesh, integrator=, threads=, options=)``."""


def mesh_hook(scheme, mesh, *, integrator=None, threads=1, options=None):
    """The driver's ``remesh`` hook of ``scheme`` (its name's ``+STRATEGY``), or None for
    a scheme without one.

    Parameters
    ----------
    scheme : mcfbench.running.schemes.Scheme
    mesh : tuple of ((n, 3) float array, (m, 3) int array)
        The run's input mesh.
    integrator : str, optional
        The run's integrator (default the scheme's).
    threads : int
    options : dict
        The run's options of the flow class.
    """
    strategy = getattr(scheme, "mesh_strategy", None) or parse_name(scheme.name).strategy
    if strategy == "none":
        return None
    return STRATEGIES[strategy](scheme, mesh, integrator=integrator, threads=threads,
                                options=options)
