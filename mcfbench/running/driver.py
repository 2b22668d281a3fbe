"""The time-stepping driver shared by every scheme.

:func:`simulate` steps a :class:`~mcfbench.running.flow.SchemeFlow` with the shared
linear solver, checks every state it reaches (the initial one included)
through :class:`mcfbench.geometry.collapse.CollapseCheck` (a component shrunk to a
point or a line, before the scheme assembles a matrix on it),
:meth:`SchemeFlow.defects` (what the scheme knows is wrong with its state) and
:class:`mcfbench.geometry.invariants.FlowInvariants` (what every mean
curvature flow must do: the area never grows, the mesh does not fold; a
solver failure on a mesh whose quality collapsed is the mesh's verdict),
calls observers at every time level and keeps frames. Every way a run can end is one :class:`~mcfbench.running.flow.SchemeFlowBreakdown`
with one message format, ``"{status} at step {n} (t = {t}): {detail}"``.
"""

import time
from dataclasses import replace

import numpy as np

from mcfbench.geometry.collapse import CollapseCheck
from mcfbench.geometry.invariants import FlowInvariants
from mcfbench.geometry.measures import StateMeasures
from mcfbench.running.flow import FlowBreakdown
from mcfbench.running.integrators import get_integrator
from mcfbench.running.solver import Solver, SolverFailure
from mcfbench.running.trajectory import Trajectory
from mcfbench.storage.frames import changing_frames

ON_DEFECT = ("stop", "record")

PROGRESS_DELAY = 2.0
"""Seconds a run goes before its progress bar appears (short runs show none)."""


class _NoBar:
    """The progress bar when there is none."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def update(self, n=1):
        pass


def simulate(flow, steps, *, solver=None, integrator="euler", warm_start="extrapolate",
             save_every=1, observers=(), on_defect="stop", until=None, progress=False,
             collapse=True, invariants=True, rebuild=None, remesh=None):
    """Step ``flow`` ``steps`` times.

    Parameters
    ----------
    flow : mcfbench.running.flow.SchemeFlow
    steps : int
    solver : mcfbench.running.solver.Solver, optional
        Default ``Solver()`` (BiCGStab, rtol 1e-9). The run steps with a copy of it:
        what the solver keeps across solves starts empty with every run.
    integrator : str
        A name of :data:`mcfbench.running.integrators.INTEGRATORS`: ``"euler"``
        (the paper's semi-implicit step) or ``"bdf2"``.
    warm_start : {"extrapolate", "previous"}
        The solver's initial guess (:class:`mcfbench.running.integrators.Euler`).
    save_every : int
        Keep every ``save_every``-th time level as a frame (the first and
        the last are always kept); ``0`` keeps only those two.
    observers : sequence of callables
        ``observer(flow)`` at every time level reached, ``n = 0`` included,
        in order.
    on_defect : {"stop", "record"}
        What an invalid state (:meth:`SchemeFlow.defects`) does: end the run
        (default; the invalid state is kept as the last frame) or be
        recorded (its first occurrence per status) while the run goes on.
        Solver failures always end the run (the state stays at the last
        valid level; :attr:`Trajectory.continue_with` goes on from there with
        another solver).
    until : callable, optional
        ``until(flow) -> bool`` after the observers of every level
        ``n >= 1``: True ends the run there (e.g. a steady state), status
        ``ok``.
    progress : bool
        A progress bar of the steps (tqdm, on standard error) once the run
        has lasted :data:`PROGRESS_DELAY` seconds, removed when it ends.
        The command line asks for it when standard error is a terminal.
    collapse : bool
        Check every state, before the scheme's own :meth:`SchemeFlow.defects` and
        before the next solve, for a component that shrank to a point or a
        line or has non-finite coordinates
        (:class:`mcfbench.geometry.collapse.CollapseCheck`): status
        ``degenerated`` naming the component; or that vanished round (a point,
        or a circle: the flow's extinction, with less than two time steps left),
        status ``extinct`` naming the component and its extinction time (an
        event of :attr:`Trajectory.events`). Either ends the run in both
        ``on_defect`` modes (there is no surface left to step).
    invariants : bool
        Check every state of the mesh (``flow.vertices``, ``flow.faces``)
        against what mean curvature flow must do
        (:class:`mcfbench.geometry.invariants.FlowInvariants`): the area may not
        grow (``area_grew``) and no triangle may fold that was not folded at
        step 0 (``inverted``); these are defects like the scheme's own. A
        solver failure on a mesh whose smallest angle collapsed ends the run
        as ``degenerated`` (the mesh's verdict), naming the angle and since
        when. Off only for toy flows that are not mean curvature flows.
    rebuild : callable, optional
        ``rebuild(flow, keep) -> flow``: the flow on the mesh vertices ``keep``
        ((n,) bool, whole components) at the same time level, or ``ValueError``
        saying why it cannot be (:func:`mcfbench.running.continuation.sub_flow`).
        When a component vanishes round and others remain, the run goes on with
        them (an ``extinct`` event of :attr:`Trajectory.events`; the frames keep the
        initial mesh's layout, the vanished points where they vanished, and the
        integrator starts afresh); without ``rebuild``, or when it cannot, the run
        ends ``degenerated`` saying why (the event's ``why_not``).
    remesh : callable, optional
        A mesh strategy's hook (:func:`mcfbench.running.remeshing.mesh_hook`):
        ``remesh(flow) -> (flow, event)`` or None, asked about every state (the initial
        one included) before its checks when ``remesh.before_checks``, else after it
        passed them: the flow on a new mesh of its surface at the same time level and
        what changed (an event). The run goes on with it, the integrator afresh, the
        checks from the new mesh. Its frames keep the layout where ``remesh.kept`` names
        the previous flow's points and triangles kept (in order, then new ones: the
        removed points where they were, the new ones left out), else carry their own
        faces (:attr:`Trajectory.frame_faces`). Its ``rollback``, if any, redoes a step
        that folded from the state before it remeshed (``on_defect="stop"``;
        :mod:`mcfbench.running.rollback`). A ``ValueError`` of the hook (a neck that
        cannot be cut, a scheme that cannot be rebuilt) ends the run ``degenerated``.

    Returns
    -------
    Trajectory
        Everything computed before a breakdown is kept.
    """
    if int(steps) != steps or steps < 0:
        raise ValueError(f"steps must be a whole number >= 0, got {steps!r}")
    if int(save_every) != save_every or save_every < 0:
        raise ValueError(f"save_every must be a whole number >= 0, got {save_every!r}")
    if on_defect not in ON_DEFECT:
        raise ValueError(f"unknown on_defect {on_defect!r}; choose one of {', '.join(ON_DEFECT)}")
    stepping = _Stepping(flow, int(steps), get_integrator(integrator, warm_start=warm_start),
                         save_every=save_every, observers=observers, on_defect=on_defect,
                         until=until, collapse=collapse, invariants=invariants,
                         rebuild=rebuild, remesh=remesh)
    # a copy per run: what a solver keeps between solves (the kept ILU factor) is the
    # run's own, built inside its timed steps, never carried in from a warm-up or an
    # earlier run (a timed repeat pays for its factor as the first execution did)
    solver = Solver() if solver is None else solver
    return stepping.go(replace(solver) if isinstance(solver, Solver) else solver, progress)


def _threads(flow):
    """The threads a flow was made with (``Scheme.make``'s ``threads``; 1 for a flow
    without them): those of the driver's measuring pass of its states."""
    return getattr(flow, "threads", 1)


class _Stepping:
    """The state of one :func:`simulate` between its steps: the flow, its integrator
    (with ``X^{n-1}, ...``), the checks, the observers, the frames and defects so
    far; :meth:`go` steps it with a solver, :meth:`continue_with` after a solver
    failure with another one."""

    def __init__(self, flow, steps, stepper, *, save_every, observers, on_defect, until,
                 collapse, invariants, rebuild=None, remesh=None):
        self.flow, self.steps, self.stepper = flow, steps, stepper
        self.save_every, self.observers, self.on_defect = save_every, observers, on_defect
        self.until = until
        self.frames, self.steps_kept, self.iterations, self.defects = [], [], [], []
        self.events = []
        self.rebuild, self.remesh, self.faces = rebuild, remesh, np.asarray(flow.faces)
        self.rollback = getattr(remesh, "rollback", None) if on_defect == "stop" else None
        self.frame_faces = []
        # the frame layout's number of every point and triangle of the flow (all until
        # a component vanishes or a neck is cut; -1 for a cap's), and the last full frame
        self.kept_vertices = np.arange(len(flow.vertices))
        self.kept_faces = np.arange(len(self.faces))
        self.full = None
        self.seen = set()
        # one compiled measuring pass per state serves both checks
        self.measures = StateMeasures(flow.vertices, flow.faces, _threads(flow)) \
            if collapse or invariants else None
        self.collapsed = CollapseCheck(flow.vertices, flow.faces, measures=self.measures,
                                       tau=flow.tau) if collapse else None
        self.invariant = FlowInvariants(flow.vertices, flow.faces, measures=self.measures) \
            if invariants else None
        self.wall = self.cpu = 0.0
        self.broken = None
        self.solver_failed = False    # the run ended with a solver failure: continuable
        self.end_frame = False        # the last frame was added when the run ended
        wall, cpu = time.perf_counter(), time.process_time()
        try:
            self.check()
            self.observe()
        except FlowBreakdown as err:
            self.broken = err
        self.save()
        if self.broken is None:
            try:
                self.remeshed()
            except FlowBreakdown as err:
                self.broken = err
        self.wall, self.cpu = time.perf_counter() - wall, time.process_time() - cpu

    def save(self):
        self.steps_kept.append(self.flow.n)
        self.frames.append(self.full_frame())
        self.frame_faces.append(self.faces)

    def remeshed(self, before_checks=False):
        """Go on with the flow on a new mesh when the mesh strategy's hook (``simulate``'s
        ``remesh``) gives one, asked where its ``before_checks`` says: the checks start
        again from it, the integrator afresh; the new state is checked (an invalid mesh
        ends the run as any state does); a hook's ``parts`` in order
        (:class:`mcfbench.running.remeshing.Strategies`). True when one operated."""
        for hook in getattr(self.remesh, "parts", (self.remesh,)):
            if hook is not None and bool(hook.before_checks) == before_checks \
                    and self.operated(hook, before_checks):
                return True
        return False

    def operated(self, hook, before_checks):
        """Ask one hook (:meth:`remeshed`): True for a new flow; ``(None, event)`` a
        refusal, recorded; its ``ValueError`` ends the run ``degenerated``."""
        flow = self.flow
        t = flow.n * flow.tau
        try:
            found = hook(flow)
        except ValueError as err:
            self.defects.append({"status": "degenerated", "step": flow.n, "time": t,
                                 "detail": str(err)})
            raise FlowBreakdown("degenerated", flow.n, t, str(err)) from None
        if found is None:
            return False
        new, event = found
        self.events.append(event)
        if new is None:                     # a refusal: the run goes on without it
            return False
        if hook.kept is not None:          # the frames keep their layout
            self.full = self.full_frame()   # the removed points stay where they were
            keep_vertices, keep_faces = hook.kept
            self.renew(new, np.flatnonzero(keep_vertices), keep_faces)
        else:                               # a new mesh: its frames carry their faces
            self.new_mesh(new)
        if not before_checks:
            self.check()
        return True

    def new_mesh(self, new):
        """Go on with ``new``, a flow on a new mesh of the surface (a remesh): its own
        layout, a fresh integrator, the checks of the new mesh."""
        check = self.collapsed
        self.flow, self.faces, self.full = new, np.asarray(new.faces), None
        self.kept_vertices = np.arange(len(new.vertices))
        self.kept_faces = np.arange(len(self.faces))
        self.stepper = get_integrator(self.stepper.name, warm_start=self.stepper.warm_start)
        if self.measures is not None:
            self.measures = StateMeasures(new.vertices, new.faces, _threads(new))
        if check is not None:
            self.collapsed = CollapseCheck(new.vertices, new.faces, measures=self.measures,
                                           tau=new.tau, area_tol=check.area_tol,
                                           diameter_tol=check.diameter_tol)
            if check.count == self.collapsed.count == 1:   # its initial size and name
                self.collapsed.renamed(check.area0, check.diameter0, check.ids,
                                       self.kept_vertices, check.total)
        if self.invariant is not None:
            self.invariant = FlowInvariants(new.vertices, new.faces, measures=self.measures)

    def check(self):
        """Record the defects of the current state; raise in stop mode (always for a
        collapse or an extinction). A component that vanished round is an extinction
        only of a state that passes the other checks (an invalid state is never counted
        as the flow's end), and at the run's last state only once it collapsed (its time
        left matters only before a next step)."""
        if self.remeshed(before_checks=True):
            return self.check()
        flow = self.flow
        # the mesh vertices once (DDFV's are a gather of its F-vertices), measured once
        # for both checks
        V = flow.vertices if self.measures is not None else None
        measured = self.measures(V) if V is not None else None
        vanished = self.collapsed(V, measured, flow.n * flow.tau,
                                  final=flow.n >= self.steps) \
            if self.collapsed is not None else None
        if vanished is not None and vanished.status != "extinct":
            self.defects.append({"status": vanished.status, "step": flow.n,
                                 "time": flow.n * flow.tau, "detail": vanished.detail})
            raise FlowBreakdown(vanished.status, flow.n, flow.n * flow.tau, vanished.detail)
        found = flow.defects()
        if self.invariant is not None:
            found = [*found, *self.invariant(V, flow.n, measured)]
        for status, detail in found:
            if status in self.seen:
                continue
            self.seen.add(status)
            self.defects.append({"status": status, "step": flow.n,
                                 "time": flow.n * flow.tau, "detail": detail})
            if self.on_defect == "stop":
                raise FlowBreakdown(status, flow.n, flow.n * flow.tau, detail)
        if vanished is not None:
            self.vanished(vanished)
            if len(vanished.components) < self.collapsed.count and self.go_on(vanished):
                return self.check()
            self.defects.append({"status": "extinct", "step": flow.n,
                                 "time": flow.n * flow.tau, "detail": vanished.detail})
            raise FlowBreakdown("extinct", flow.n, flow.n * flow.tau, vanished.detail)

    def vanished(self, found):
        """Record the components of an ``extinct`` :class:`~mcfbench.geometry.collapse.Collapse`
        as events of the run (the components numbered as in the initial mesh)."""
        flow = self.flow
        for c, kind, area, volume, time in zip(found.components, found.kinds, found.areas,
                                               found.volumes, found.times):
            self.events.append({"event": "extinct", "step": flow.n, "time": flow.n * flow.tau,
                                "component": int(self.collapsed.ids[c]), "kind": kind,
                                "area": area, "volume": volume, "extinction_time": time})

    def go_on(self, found):
        """Drop the vanished components of ``found`` and go on with the flow rebuilt on
        the rest (``rebuild``, :mod:`mcfbench.running.continuation`); True when it
        did. Else the last event says why not, and the run ends ``degenerated``."""
        check, flow = self.collapsed, self.flow
        keep = ~np.isin(check.labels, found.components)
        try:
            if self.rebuild is None:
                raise ValueError("no continuation given (simulate's rebuild)")
            new = self.rebuild(flow, keep)
        except ValueError as err:
            self.events[-1]["continued"] = False
            self.events[-1]["why_not"] = str(err)
            found = found._replace(status="degenerated", detail=(
                f"{found.detail}; the run cannot go on without it: {err}"))
            self.defects.append({"status": "degenerated", "step": flow.n,
                                 "time": flow.n * flow.tau, "detail": found.detail})
            raise FlowBreakdown("degenerated", flow.n, flow.n * flow.tau, found.detail) \
                from None
        self.full = self.full_frame()          # the vanished vertices stay where they were
        kept_faces = keep[np.asarray(flow.faces)].all(axis=1)
        self.renew(new, np.flatnonzero(keep), kept_faces)
        return True

    def renew(self, new, old_vertices, kept_faces):
        """Go on with ``new``, a flow on the previous one's points ``old_vertices`` (in
        its numbering, in order) and its triangles ``kept_faces`` ((m,) bool), then new
        points and triangles: the layout of the frames, a fresh integrator, the checks
        of the new mesh (the components keep their initial size and names, the second
        piece of a component cut in two is named as a new one)."""
        check = self.collapsed
        added_v = len(new.vertices) - len(old_vertices)
        added_f = len(new.faces) - int(np.sum(kept_faces))
        self.kept_vertices = np.r_[self.kept_vertices[old_vertices], np.full(added_v, -1)]
        self.kept_faces = np.r_[self.kept_faces[kept_faces], np.full(added_f, -1)]
        self.flow = new
        self.stepper = get_integrator(self.stepper.name, warm_start=self.stepper.warm_start)
        self.measures = StateMeasures(new.vertices, new.faces, _threads(new)) \
            if self.measures is not None else None
        if check is not None:
            collapsed = CollapseCheck(new.vertices, new.faces, measures=self.measures,
                                      tau=new.tau, area_tol=check.area_tol,
                                      diameter_tol=check.diameter_tol)
            # a component's first point is one of the previous flow's (they come first)
            old = check.labels[old_vertices[collapsed.first]]
            ids = check.ids[old].copy()
            again = np.ones(len(old), bool)
            again[np.unique(old, return_index=True)[1]] = False
            ids[again] = check.total + np.arange(int(again.sum()))
            collapsed.renamed(check.area0[old], check.diameter0[old], ids,
                              self.kept_vertices, check.total + int(again.sum()))
            self.collapsed = collapsed
        if self.invariant is not None:
            self.invariant = FlowInvariants(new.vertices, new.faces, measures=self.measures)

    def full_frame(self):
        """The current frame in the initial mesh's layout: the vanished components'
        points where they were when they vanished, the points a surgery removed where
        they were then, its caps' points left out."""
        frame = self.flow.frame()
        if self.full is None:
            return frame
        full = {key: value.copy() for key, value in self.full.items()}
        kept = self.kept_vertices >= 0
        full["vertices"][self.kept_vertices[kept]] = frame["vertices"][kept]
        if "extra_points" in full:
            kept = self.kept_faces >= 0
            full["extra_points"][self.kept_faces[kept]] = frame["extra_points"][kept]
        return full

    def observe(self):
        for observer in self.observers:
            observer(self.flow)

    def step(self, solver):
        """One time step, checked; raises :class:`FlowBreakdown`. False when the step
        folded and was rolled back (:meth:`rolled_back`)."""
        flow = self.flow
        if self.rollback is not None:
            self.rollback.keep(flow)
        try:
            info = self.stepper.step(flow, solver)
        except SolverFailure as err:
            step = flow.n + 1
            status, detail = err.status, str(err)
            collapse = self.invariant.quality_collapse() if self.invariant is not None \
                else None
            if collapse is not None:
                status, detail = "degenerated", f"{collapse}; then {detail}"
            self.defects.append({"status": status, "step": step, "time": step * flow.tau,
                                 "detail": detail})
            self.solver_failed = collapse is None
            raise FlowBreakdown(status, step, step * flow.tau, detail) from None
        self.iterations.append(info.iterations)
        try:
            self.check()
        except FlowBreakdown as err:
            return self.rolled_back(err)
        return True

    def rolled_back(self, err):
        """After ``err`` of a step's new state: go on from the state before the step
        remeshed when the hook's ``rollback`` gives it (a fold,
        :mod:`mcfbench.running.rollback`), the step's defect and iterations forgotten
        (False); its event recorded; else raise ``err``."""
        found = self.rollback(self.flow, err) if self.rollback is not None else None
        if found is not None:
            self.events.append(found[1])
        if found is None or found[0] is None:
            raise err
        self.defects.pop()
        self.seen.discard(err.status)
        self.iterations.pop()
        self.new_mesh(found[0])
        self.check()
        return False

    def go(self, solver, progress=False):
        """Step with ``solver`` until the run's end, a breakdown or ``until``; the
        :class:`Trajectory` of the whole run so far (its flow may be rebuilt on the
        remaining components: read ``self.flow``)."""
        wall, cpu = time.perf_counter(), time.process_time()
        if progress and self.broken is None:
            from tqdm import tqdm  # on first use: not paid at start-up without a bar

            bar = tqdm(total=self.steps, initial=len(self.iterations), delay=PROGRESS_DELAY,
                       unit="step", leave=False)
        else:
            bar = _NoBar()
        with bar:
            while self.broken is None and len(self.iterations) < self.steps:
                try:
                    if not self.step(solver):
                        continue                # rolled back: the step again
                except FlowBreakdown as err:
                    self.broken = err
                    break
                finally:
                    bar.update()
                self.observe()
                if self.save_every and self.flow.n % self.save_every == 0:
                    self.save()
                if self.until is not None and self.until(self.flow):
                    break
                try:
                    self.remeshed()
                except FlowBreakdown as err:
                    self.broken = err
                    break
        self.end_frame = self.steps_kept[-1] != self.flow.n
        if self.end_frame:
            self.save()
        self.wall += time.perf_counter() - wall
        self.cpu += time.process_time() - cpu
        return self.trajectory()

    def continue_with(self, solver, progress=False):
        """:meth:`Trajectory.continue_with`."""
        if not self.solver_failed:
            raise ValueError("only a run that ended with a solver failure can be continued, "
                             "and only once")
        self.solver_failed, self.broken = False, None
        self.defects.pop()                  # the failure: the run goes on past it
        if self.end_frame:                  # the failed step's state, kept as its end
            self.steps_kept.pop()
            self.frames.pop()
            self.frame_faces.pop()
        return self.go(solver, progress)

    def trajectory(self):
        flow, defects = self.flow, list(self.defects)
        status, message, failed = "ok", "", -1
        if defects:
            first = defects[0]
            status, failed = first["status"], first["step"]
            message = str(self.broken) if self.broken is not None else str(
                FlowBreakdown(first["status"], first["step"], first["time"], first["detail"]))
        frame_faces = None
        if all(faces is self.frame_faces[0] for faces in self.frame_faces):
            stacked = {key: np.stack([frame[key] for frame in self.frames])
                       for key in self.frames[0]}
        else:                                 # remeshed: each frame its own mesh
            frame_faces = list(self.frame_faces)
            extra = [frame["extra_points"] for frame in self.frames] \
                if "extra_points" in self.frames[0] else None
            stacked = changing_frames([frame["vertices"] for frame in self.frames], extra,
                                      frame_faces)
            del stacked["faces"]
        return Trajectory(
            frames=stacked, steps=np.array(self.steps_kept),
            t=np.array(self.steps_kept) * flow.tau, faces=self.frame_faces[0],
            frame_faces=frame_faces,
            iterations=np.array(self.iterations, dtype=int), status=status, message=message,
            failed_step=failed, steps_done=len(self.iterations), defects=defects,
            wall_seconds=self.wall, cpu_seconds=self.cpu, events=list(self.events),
            flow=flow, continue_with=self.continue_with if self.solver_failed else None)
