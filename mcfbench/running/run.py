"""Studies for ANY scheme on ANY problem: one run, level sweeps, time and space convergence.

:func:`run` is the single place where a scheme meets a problem: it builds
the problem's mesh, validates it, builds the scheme's flow, steps it with
the shared solver and driver, and measures the problem's metrics, the mesh
quality over time, iterations and time. Table 3.1 is
``[run("ddfv", "sphere", k) for k in 1..5]`` (:func:`level_sweep`).

Convergence in time and in space separately (beyond Table 3.1):
:func:`time_convergence` (fixed mesh, tau halved, against a fine-tau
reference of the same scheme: order 1 expected, (2.1)) and
:func:`space_convergence` (one tiny tau, refined meshes, against the exact
solution: order 2 expected).
"""

import time
from dataclasses import dataclass, replace
from functools import partial

import numpy as np

from mcfbench.geometry import metrics
from mcfbench.geometry.exact import eoc
from mcfbench.geometry.mesh import validate_mesh
from mcfbench.running.continuation import exceeded, sub_flow
from mcfbench.running.cost import check_size
from mcfbench.running.driver import simulate
from mcfbench.running.locality import intake, locality_order, stepped
from mcfbench.running.monitors import Monitor, Steady
from mcfbench.running.problems import get_problem
from mcfbench.running.remeshing import mesh_hook
from mcfbench.running.schemes import get_scheme
from mcfbench.running.solver import Solver
from mcfbench.storage.frames import surface_points
from mcfbench.storage.records import RunResult


def run(scheme, problem, level, *, tau=None, t_final=None, solver=None, integrator=None,
        warm_start="extrapolate", on_defect="stop", save_every=0, samples=20, mesh=None,
        threads=1, progress=False, observers=(), force=False, robust=None, **options):
    """Run ``scheme`` on ``problem`` at refinement ``level``.

    Parameters
    ----------
    scheme : str or mcfbench.running.schemes.Scheme
    problem : str or mcfbench.running.problems.Problem
    level : int
    tau, t_final : float, optional
        Override the problem's time rule.
    solver : mcfbench.running.solver.Solver, optional
        Default: BiCGStab, rtol 1e-9 (the paper's).
    integrator : {"euler", "bdf2", "bdf3"}, optional
        The time integrator (:mod:`mcfbench.running.integrators`); default
        the scheme's (:attr:`mcfbench.running.schemes.Scheme.integrator`).
    warm_start : {"extrapolate", "previous"}
        The solver's initial guess (:class:`mcfbench.running.integrators.Euler`).
    on_defect : {"stop", "record"}
        See :func:`mcfbench.running.driver.simulate`.
    save_every : int
        Frames kept in the returned trajectory (``0``: first and last).
    samples : int
        About how many time levels the mesh quality is sampled at.
    mesh : (vertices, faces), optional
        Instead of the problem's generator (a user's mesh).
    threads : int
        Threads of the solver and of the scheme's compiled passes
        (:meth:`mcfbench.running.schemes.Scheme.make`); ``solver.threads`` is
        replaced by it when more than one.
    progress : bool
        A progress bar of the steps (:func:`mcfbench.running.driver.simulate`).
    observers : sequence of callables
        Called with the flow at every time level, after the run's own (the
        figures' :class:`mcfbench.geometry.quality.MeshQuality`); not called
        again when a short run is timed again (their state is the caller's).
    force : bool
        Run even when its estimated memory is above the machine's available
        memory (:func:`mcfbench.running.cost.check_size`, checked before the
        mesh is built).
    robust : mcfbench.running.solver.Solver, optional
        A run that ends with a solver failure (a ``solver_*`` status) is
        continued with this solver from its last accepted state (the failed step
        tried again with it; :attr:`mcfbench.running.trajectory.Trajectory.continue_with`):
        the flow with its T-vertices, the integrator's past states (BDF2, BDF3),
        the monitors, the metric observers and the driver's checks are exactly
        those of the run at that step, so that the result is that of the whole run
        with ``robust`` from ``t = 0`` up to the solvers' tolerances (the robust
        re-run of every run of the run store, :func:`mcfbench.running.batch.run_spec`).
        Not when the run used ``robust``'s method already.
    **options
        Options of the scheme's flow class (override the registry's).

    A large mesh is stepped renumbered for locality, everything given back in its
    numbering (:func:`mcfbench.running.locality.locality_order`), but for a run that
    changes its mesh (``NAME+remesh``, ``NAME+surgery``).

    Returns
    -------
    result : RunResult
        Its times are those of the flow alone: the scheme is warmed up first
        (:func:`warm_up`), and a run under :data:`SHORT_RUN` CPU seconds is
        timed again, up to :data:`MAX_REPEATS` times in about
        :data:`REPEAT_BUDGET` seconds, the best kept (``timing_repeats``); its
        numbers are those of the first execution.
    trajectory : mcfbench.running.trajectory.Trajectory
        The run's (not the continued run's).
    continued : RunResult or None
        Only with ``robust``: the continued run (None when there was none): its
        ``solver`` is ``robust``'s method, ``steps_done``, ``iterations``, status,
        metrics and quality those of the whole run, ``cpu_seconds`` and
        ``wall_seconds`` those of the continuation alone (after the failure, the
        robust solver warmed up first; timed once).

    Raises
    ------
    mcfbench.running.cost.RunTooLarge
        A ``ValueError``: the run's estimated memory is above the available
        memory (unless ``force``).
    """
    scheme = get_scheme(scheme) if isinstance(scheme, str) else scheme
    problem = get_problem(problem) if isinstance(problem, str) else problem
    integrator = scheme.integrator if integrator is None else integrator
    mesh = None if mesh is None else validate_mesh(*mesh)      # a bad one named first
    check_size(scheme, problem, level, mesh=mesh, tau=tau, t_final=t_final, force=force)
    V, F = problem_mesh(problem, level) if mesh is None else mesh
    tau = problem.tau(level, (V, F)) if tau is None else float(tau)
    steps = problem.time_steps(tau, t_final)
    solver = Solver() if solver is None else solver
    if threads != 1:
        solver = replace(solver, threads=threads)
    setup = {"solver": solver, "integrator": integrator, "warm_start": warm_start,
             "on_defect": on_defect, "threads": threads, "samples": samples,
             "options": options}
    warm_up(scheme, problem, F, progress=progress, **setup)
    order = locality_order(V, F) if scheme.mesh_strategy == "none" else None
    timed = _timed_run(scheme, problem, (V, F), tau, steps, save_every=save_every,
                       progress=progress, observers=observers, order=order, **setup)
    traj = timed.trajectory
    cpu, wall, repeats, spent = timed.cpu, timed.wall, 1, timed.cpu
    while cpu < SHORT_RUN and repeats < MAX_REPEATS and spent < REPEAT_BUDGET:
        again = _timed_run(scheme, problem, (V, F), tau, steps, save_every=save_every,
                           progress=False, observers=(), order=order, **setup)
        cpu, wall = min(cpu, again.cpu), min(wall, again.wall)
        repeats, spent = repeats + 1, spent + again.cpu
    h = metrics.mean_edge_length(V, F)
    result = _result(timed, scheme, problem, level, len(V), h, tau, steps, solver.method,
                     integrator, cpu, wall, repeats)
    if robust is None:
        return result, traj
    if traj.continue_with is None or robust.method == solver.method:
        return result, traj, None
    warm_up(scheme, problem, F, progress=progress, **{**setup, "solver": robust})
    continued = _continued(timed, robust, progress)
    return result, traj, _result(continued, scheme, problem, level, len(V), h, tau, steps,
                                 robust.method, integrator, continued.cpu, continued.wall, 1)


def _result(timed, scheme, problem, level, nF, h, tau, steps, method, integrator, cpu, wall,
            repeats):
    """The :class:`RunResult` of an execution of a run (:func:`_timed_run`,
    :func:`_continued`) with ``nF`` mesh vertices of mean edge length ``h``."""
    flow, traj, monitor = timed.flow, timed.trajectory, timed.monitor
    nV = sum(len(points[0]) for points in surface_points(traj.frames) if points is not None)
    q = monitor.quality
    return RunResult(
        scheme=scheme.name, problem=problem.name, level=int(level), nV=nV,
        nF=nF, nT=nV - nF, h=h, tau=tau, N=steps, steps_done=traj.steps_done,
        status=traj.status, message=traj.message, t_failed=traj.t_failed,
        t_end=flow.n * tau, steady=bool(timed.steady),
        iterations=int(traj.iterations.sum()), solver=method, integrator=integrator,
        cpu_seconds=cpu, wall_seconds=wall, t_min_barycentric=_worst(np.min, monitor.t_monitor),
        min_angle=_worst(np.min, q["min_angle"]), max_aspect=_worst(np.max, q["max_aspect"]),
        max_flipped=_worst(np.max, q["flipped"]), metrics=_metric_values(timed, problem),
        series={"t": monitor.t, "t_min_barycentric": monitor.t_monitor, **q},
        timing_repeats=repeats, removed_area_share=traj.removed_area_share,
        surgery_exceeded=exceeded(traj.removed_area_share),
        rollbacks=sum(event["event"] == "rolled_back" for event in traj.events))


def problem_mesh(problem, level):
    """The validated mesh ``(vertices, faces)`` of ``problem``'s ``level``: copies of the
    one built once per process (the last :data:`KEPT_MESHES`). The series of a
    matrix batch share a problem and its levels, and a real mesh's file takes
    0.1-0.3 s to read and validate (22 series on ``real_kitten`` in one process
    read it 22 times). A problem whose parameters are not hashable (an array)
    builds it every time."""
    try:
        key = (problem.surface, tuple(sorted(problem.params(int(level)).items())))
        hash(key)
    except TypeError:
        return validate_mesh(*problem.mesh(level))
    if key not in _kept_meshes:
        if len(_kept_meshes) >= KEPT_MESHES:
            del _kept_meshes[next(iter(_kept_meshes))]      # the oldest
        _kept_meshes[key] = validate_mesh(*problem.mesh(level))
    V, F = _kept_meshes[key]
    return V.copy(), F.copy()


KEPT_MESHES = 8
"""Meshes :func:`problem_mesh` keeps (a problem's levels, several problems)."""
_kept_meshes = {}
"""(surface, parameters) -> validated mesh (:func:`problem_mesh`)."""


SHORT_RUN = 0.01
"""CPU seconds below which a run is too short to time once: its timed part is run
again and the best time kept, as :mod:`timeit` does (:func:`run`)."""
REPEAT_BUDGET = 0.2
"""CPU seconds all the executions of a short run may take together (about)."""
MAX_REPEATS = 25
"""Most executions of a short run's timed part."""


@dataclass
class _Timed:
    """One execution of the timed part of a run (:func:`_timed_run`)."""

    flow: object
    trajectory: object
    monitor: Monitor
    """The run's monitor with the last state's sample (:meth:`Monitor.finished`)."""
    running: Monitor
    """The monitor as the stepping left it (a continued run goes on with it)."""
    metric_observers: list
    until: object
    cpu: float
    wall: float

    @property
    def steady(self):
        return self.until is not None and self.until.reached


def _timed_run(scheme, problem, mesh, tau, steps, *, solver, integrator, warm_start,
               on_defect, threads, samples, options, save_every, progress, observers, order=None):
    """The part of a run whose CPU and wall times are recorded: the flow's
    construction, the stepping with its checks, monitor and observers, the last
    quality sample. Not timed: the mesh's construction and validation, the warm-up
    (:func:`warm_up`), the metrics' final values, ``order``'s renumbering and undoing."""
    at = intake(order, scheme, mesh, options, observers)    # renumbered for locality
    V, F = at.mesh
    monitor = Monitor(max(1, steps // max(1, samples)))
    metric_observers = problem.observers()
    until = Steady(problem.steady_speed) if problem.steady_speed else None
    cpu, wall = time.process_time(), time.perf_counter()
    flow = at.make(V, F, tau, threads=threads, **at.options)
    traj = simulate(flow, steps, solver=solver, integrator=integrator, warm_start=warm_start,
                    save_every=save_every,
                    observers=[monitor, *metric_observers, *at.observers], on_defect=on_defect,
                    until=until, progress=progress,
                    rebuild=at.rebuild(partial(sub_flow, scheme, integrator=integrator,
                                               threads=threads, **at.options)),
                    remesh=mesh_hook(scheme, (V, F), integrator=integrator, threads=threads,
                                     options=options))
    flow = traj.flow                      # rebuilt when a component vanished
    finished = monitor.finished(flow)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    return _Timed(flow, at.trajectory(traj), finished, monitor, metric_observers, until, cpu,
                  wall)


def _continued(timed, solver, progress):
    """The run of ``timed`` (ended with a solver failure) continued with ``solver`` from
    its last accepted state (:attr:`mcfbench.running.trajectory.Trajectory.continue_with`),
    its monitor and observers going on; timed alone."""
    cpu, wall = time.process_time(), time.perf_counter()
    traj = timed.trajectory.continue_with(solver, progress=progress)
    flow = stepped(traj.flow)               # not the view in the input's order
    finished = timed.running.finished(flow)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    return replace(timed, flow=flow, trajectory=traj, monitor=finished, cpu=cpu, wall=wall)


WARM_UP_STEPS = 3
"""Time steps of a warm-up run: the integrator's start and its regular step (BDF2's
first step is Euler's), the solver's extrapolated initial guess (from step 2)."""
_warmed = set()
"""The warm-ups done in this process (:func:`warm_up`)."""


def warm_up(scheme, problem, faces, *, solver, integrator, warm_start, on_defect, threads,
            samples, options, progress=False):
    """Run ``scheme`` :data:`WARM_UP_STEPS` steps on a tiny mesh of the kind of ``faces``,
    once per process for each scheme, integrator, solver method, thread count, kind of
    mesh (closed or not), set of metrics and the scheme's options, so that a run's
    time is that of its flow alone.

    Done before the clock of :func:`run` starts: the first call of every compiled
    kernel (numba's compilation, or the loading of its cache: the scheme's, the
    shared BiCGStab's, the driver's collapse and invariant checks, the quality and
    error metrics), the imports and first-call set-ups of the scheme, the solver, the
    integrator and the problem's metric observers at every time level (their final
    values are not timed: not warmed up).
    Before, level 1 of the sphere timed first carried 0.10-0.14 s of these against
    0.0014-0.0036 s timed second (cotan, DDFV, BGN; issue 32).

    The tiny mesh is the level-1 icosphere (42 vertices) for a closed ``faces``, a
    hemisphere of 3 rings (37 vertices, the equator fixed) for one with a boundary:
    fixed vertices take other code paths. Its time step ``0.01 h^2`` barely moves
    it. Options that are arrays (``T0``: data of the run's own mesh) are left out.
    A scheme that refuses the tiny mesh (a ``ValueError`` of its constructor) is not
    warmed up: the run will say whether it refuses its own mesh.

    Parameters
    ----------
    scheme, problem : registry entries
    faces : (m, 3) int array
        The run's mesh (only whether it has a boundary is used).
    solver, integrator, warm_start, on_defect, threads, samples, options, progress
        As in :func:`run`.
    """
    from mcfbench.geometry.surfaces import make_surface

    boundary = has_boundary(faces)
    options = {k: v for k, v in options.items() if np.ndim(v) == 0}
    key = (scheme.name, integrator, solver.method, threads, boundary, problem.metrics,
           tuple(sorted((k, repr(v)) for k, v in options.items())))
    if key in _warmed:
        return
    _warmed.add(key)
    V, F = make_surface("hemisphere", rings=3, radius=1.0) if boundary else \
        make_surface("sphere", level=1, radius=1.0)
    tau = 0.01 * metrics.mean_edge_length(V, F) ** 2
    try:
        _timed_run(scheme, problem, (V, F), tau, WARM_UP_STEPS, solver=solver,
                   integrator=integrator, warm_start=warm_start, on_defect=on_defect,
                   threads=threads, samples=samples, options=options, save_every=1,
                   progress=progress, observers=())
    except (ValueError, _Unsupported):
        pass


def has_boundary(faces):
    """Whether the mesh of ``faces`` (a valid one: every edge in one or two
    triangles) has a boundary edge: fewer than ``3 m / 2`` edges shared by two
    triangles."""
    return 2 * len(metrics.edge_neighbours(faces)[0]) < 3 * len(faces)


def _metric_values(timed, problem):
    """The problem's metrics at the end of a run (NaN for a run that did not finish,
    but for observers that keep their values from before a breakdown)."""
    traj = timed.trajectory
    values = {}
    for observer in timed.metric_observers:
        kept = traj.ok or getattr(observer, "keeps_before_breakdown", False)
        values.update({k: v if kept else float("nan") for k, v in observer.result().items()})
    if "pinch_time" in problem.reference:
        values["pinch_time_error"] = pinch_time_error(traj, problem.reference["pinch_time"])
    extinction = problem.reference.get("extinction_time", problem.t_max)
    if problem.to_extinction and extinction is not None:
        values["extinction_time_error"] = traj.extinction_time / extinction - 1.0
    return values


def pinch_time_error(traj, pinch_time):
    """Relative error ``t / pinch_time - 1`` of ``t``: the first cut's ``pinch_time``
    (a run that cut a neck), the ``extinction_time`` of a run that ended ``extinct``
    (:attr:`mcfbench.running.trajectory.Trajectory.extinction_time`), else ``t_failed``;
    NaN for a run that finished."""
    if traj.surgeries:
        return traj.surgeries[0]["pinch_time"] / pinch_time - 1.0
    if traj.ok:
        return float("nan")
    return (traj.extinction_time if traj.status == "extinct" else traj.t_failed) / pinch_time - 1


def _worst(reduce, values):
    """``reduce`` of a series, NaN for an empty one."""
    return float(reduce(values)) if len(values) else float("nan")


def level_sweep(scheme, problem, levels=None, *, progress=False, **options):
    """:func:`run` on each level and the EOC (3.1) of every metric.

    Parameters
    ----------
    scheme, problem : str or registry entry
    levels : sequence of int, optional
        Default: the problem's.
    progress : bool
        A progress bar of the levels (tqdm, on standard error), and of each
        run's steps below it (:func:`run`).
    **options
        Passed to :func:`run`.

    Returns
    -------
    pandas.DataFrame
        One row per level: :meth:`RunResult.to_dict` without series, and
        ``eoc_<metric>`` against the previous level when that is one coarser.
    """
    problem = get_problem(problem) if isinstance(problem, str) else problem
    levels = [int(level) for level in (problem.levels if levels is None else levels)]
    import pandas as pd  # on first use: importing pandas takes 0.1-0.2 s

    bar = _level_bar(levels, problem) if progress else None
    results = []
    for level in levels:
        if bar is not None:
            bar.set_postfix_str(f"level {level}")
        results.append(run(scheme, problem, level, progress=progress, **options)[0])
        if bar is not None:
            bar.update()
    if bar is not None:
        bar.close()
    table = pd.DataFrame([r.to_dict(series=False) for r in results])
    for name in results[0].metrics:
        table[f"eoc_{name}"] = eoc(table[name], levels=levels)
    return table


def _level_bar(levels, problem):
    """The progress bar of a level sweep (tqdm imported on first use), wiped when
    closed as the steps' bar is (:func:`mcfbench.running.driver.simulate`)."""
    from tqdm import tqdm

    return tqdm(total=len(levels), desc=problem.name, unit="level", leave=False)


def time_convergence(scheme, problem, level, taus, *, reference_factor=8, t_final=None,
                     solver=None, integrator=None, **options):
    """Error at ``t_final`` against a fine-``tau`` reference of the same scheme on one mesh.

    Parameters
    ----------
    scheme, problem : str
    level : int
        Fixed mesh.
    taus : sequence of float
        Time steps, each dividing ``t_final``; usually halved repeatedly.
    reference_factor : int
        The reference uses ``min(taus) / reference_factor``.
    t_final : float, optional
        Default: the problem's.
    solver : mcfbench.running.solver.Solver, optional
    integrator : {"euler", "bdf2", "bdf3"}, optional
        The time integrator of every run, the reference's included (default
        the scheme's).
    **options
        Options of the scheme's flow (passed to :func:`run`).

    Returns
    -------
    pandas.DataFrame
        Columns ``tau, N, error, eoc, volume_error, volume_eoc, <metrics>, status``:
        ``error`` and ``volume_error`` at ``t_final``
        (:func:`mcfbench.geometry.metrics.final_state_distance`: the weighted distance
        of every point, and the volume between the surfaces, blind to the tangential
        motion BGN sets anew at every step); ``eoc``, ``volume_eoc`` their orders (3.1)
        between successive rows.

    Raises
    ------
    RuntimeError
        The reference run broke down (its message).
    """
    import pandas as pd

    from mcfbench.geometry.metrics import final_state_distance

    def final(tau):
        result, traj = run(scheme, problem, level, tau=tau, t_final=t_final, solver=solver,
                           integrator=integrator, **options)
        if traj.frame_faces is not None:          # remeshed: other vertices than the input's
            raise ValueError(f"{result.scheme} remeshed the run at tau = {tau:g}: its final "
                             "state is not on the input's mesh, which the time study compares")
        return result, {**traj.frames, "faces": traj.faces}

    ref_result, ref = final(min(taus) / reference_factor)
    if ref_result.status != "ok":
        raise RuntimeError(f"reference run failed: {ref_result.message}")
    weights = final_weights(scheme, ref, options)
    rows = []
    for tau in taus:
        result, frames = final(tau)
        ok = result.status == "ok"
        error, volume_error = final_state_distance(frames, ref, weights) if ok else \
            (np.nan, np.nan)
        rows.append({"tau": tau, "N": result.N, "error": error, "volume_error": volume_error,
                     **result.metrics, "status": result.status})
    table = pd.DataFrame(rows)
    table.insert(3, "eoc", eoc(table["error"].to_numpy()))
    table.insert(5, "volume_eoc", eoc(table["volume_error"].to_numpy()))
    return table


def final_weights(scheme, frames, options=None):
    """The scheme's quadrature weights ``flow.l2_weights`` of the last frame of
    ``frames`` (:mod:`mcfbench.storage.frames`' layout): (n_points,) float array
    (DDFV: the covolumes of its F- and T-vertices), its flow made from that state
    (``options``: the scheme's)."""
    scheme = get_scheme(scheme) if isinstance(scheme, str) else scheme
    vertices, extra = surface_points(frames)
    T0 = {"T0": extra[-1]} if scheme.extra_points else {}
    flow = scheme.make(vertices[-1], frames["faces"], 1.0, **{**(options or {}), **T0})
    return np.asarray(flow.l2_weights)


def space_convergence(scheme, problem, levels, tau, *, t_final=None, **options):
    """The problem's metrics on refined meshes with one small ``tau``, with EOC.

    Returns
    -------
    pandas.DataFrame
        As :func:`level_sweep`.
    """
    return level_sweep(scheme, problem, levels, tau=tau, t_final=t_final, **options)


class _Unsupported(Exception):
    """The scheme refused the surface (a ValueError of its constructor)."""


class _Guarded:
    """A scheme (its fields) whose constructor's ValueError becomes :class:`_Unsupported`."""

    def __init__(self, scheme):
        self.scheme = scheme

    def __getattr__(self, name):                # called for the fields alone
        return getattr(self.__dict__["scheme"], name)

    def make(self, vertices, faces, tau, **options):
        try:
            return self.scheme.make(vertices, faces, tau, **options)
        except ValueError as err:
            raise _Unsupported(str(err)) from err


def failed_result(scheme, problem, level, status, message, *, steps, method, mesh=None,
                  tau=float("nan"), seconds=0.0):
    """The result of a run that did not take a step: ``status`` and ``message`` (a
    scheme that refuses the surface, a mesh file the reader refused), NaN measures.

    Parameters
    ----------
    scheme : Scheme
        Its ``name`` and ``integrator`` are recorded.
    problem : Problem
        Its ``name`` is recorded.
    mesh : (V, F), optional
        The mesh when there is one (its sizes and ``h``); None: 0 vertices, ``h`` NaN.
    steps : int
        The steps the run was to take (``N``).
    method : str
        The solver's method.
    seconds : float
        CPU (and wall) seconds spent.
    """
    nan = float("nan")
    nV, h = (len(mesh[0]), metrics.mean_edge_length(*mesh)) if mesh is not None else (0, nan)
    return RunResult(
        scheme=scheme.name, problem=problem.name, level=int(level), nV=nV, nF=nV,
        nT=0, h=h, tau=float(tau), N=int(steps), steps_done=0,
        status=status, message=message, t_failed=0.0, t_end=0.0, steady=False, iterations=0,
        solver=method, integrator=scheme.integrator, cpu_seconds=seconds, wall_seconds=seconds,
        t_min_barycentric=nan, min_angle=nan, max_aspect=nan, max_flipped=nan, metrics={},
        series={})


def framed_run(scheme, problem, level, *, solver, mesh=None, tau=None, save_every=0,
               on_defect="stop", observers=(), robust=None, **options):
    """:func:`run` for the studies that keep frames files (by default the first and the
    last, ``save_every=0``; see :func:`mcfbench.running.driver.simulate`); a scheme
    that refuses the surface gives status ``unsupported`` (the initial surface as both
    frames). ``on_defect``, ``observers``, ``robust`` and ``options`` (the scheme's) go
    to :func:`run`.

    Returns
    -------
    result : RunResult
    frames : dict of arrays
        The trajectory's saved frames, ``faces``, ``steps``, ``t``: the layout of
        :mod:`mcfbench.storage.frames` (the run's, not the continued run's).
    continued : RunResult or None
        Only with ``robust``: :func:`run`'s.
    """
    scheme = get_scheme(scheme) if isinstance(scheme, str) else scheme
    problem = get_problem(problem) if isinstance(problem, str) else problem
    start = time.process_time()
    try:
        result, traj, *continued = run(
            _Guarded(scheme), problem, level, solver=solver, save_every=save_every,
            mesh=mesh, tau=tau, on_defect=on_defect, observers=observers, robust=robust,
            **options)
    except _Unsupported as err:
        V, F = problem_mesh(problem, level) if mesh is None else validate_mesh(*mesh)
        tau = problem.tau(level, (V, F)) if tau is None else float(tau)
        steps = problem.time_steps(tau)
        result = failed_result(scheme, problem, level, "unsupported",
                               f"unsupported at step 0 (t = 0): {err}", steps=steps,
                               method=solver.method, mesh=(V, F), tau=tau,
                               seconds=time.process_time() - start)
        frames = {"vertices": np.stack([V, V]), "faces": F, "steps": np.array([0, 0]),
                  "t": np.zeros(2)}
        return (result, frames) if robust is None else (result, frames, None)
    frames = dict(traj.frames)
    frames.update(faces=traj.faces, steps=traj.steps, t=traj.t)     # frame 0's faces
    return (result, frames, *continued)
