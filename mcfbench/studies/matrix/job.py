"""One run of the benchmark matrix (:func:`job`), the series of one scheme on one
problem (:func:`series_job`) and several of them in one process (:func:`batch_job`,
the Snakemake job)."""

import logging

from mcfbench.running.run import framed_run
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.matrix.plan import level_of, scheme_of


def job(settings, record, frames, log_path=None):
    """One run of the matrix: the record (:func:`mcfbench.storage.records.write_record`,
    with ``metric_names``) and the first and last frames (npz), both atomic.
    ``log_path``: the job's log file (set up here); None logs to the logger that
    the caller set up (:func:`series_job`, one log for a series).

    A run that ends with a ``solver_*`` status is continued with the scheme's robust
    solver (:attr:`mcfbench.running.schemes.Scheme.robust_solver`, ``jacobi-direct``) at the
    same tolerance from its last accepted state, the failed step tried again
    (:func:`mcfbench.running.run.run`'s ``robust``: the result is that of a re-run
    from ``t = 0`` with the robust solver up to the solvers' tolerances, at the
    cost of the steps after the failure only), to tell the solver's failure from
    the scheme's: the record gets :func:`robust_fields` (``robust_status`` empty
    when there was none); the frames stay those of the run itself."""
    from dataclasses import replace

    from mcfbench.running.schemes import get_scheme
    from mcfbench.running.solver import Solver
    from mcfbench.storage.frames import save_frames
    from mcfbench.storage.records import write_record

    log = setup_logging(log_path) if log_path else logging.getLogger("pipeline")
    solver = Solver.of_settings(settings)
    log.info("%s on %s level %d, solver %s", settings["scheme"], settings["problem"],
             settings["level"], solver.method)
    scheme = get_scheme(settings["scheme"])
    result, arrays, robust = framed_run(scheme, settings["problem"], settings["level"],
                                        solver=solver,
                                        robust=replace(solver, method=scheme.robust_solver))
    save_frames(frames, arrays)
    write_record(record, result, settings, metric_names=list(result.metrics),
                 **robust_fields(robust))
    log.info("%s; %d/%d steps, %s, %.1f s CPU -> %s", result.status, result.steps_done,
             result.N, ", ".join(f"{k} {v:.4g}" for k, v in result.metrics.items()),
             result.cpu_seconds, record)
    if result.status != "ok":
        log.warning("%s", result.message)
    if robust is not None:
        log.info("continued with %s from step %d: %s%s, %.1f s CPU", robust.solver,
                 result.steps_done, robust.status,
                 f" ({robust.message})" if robust.message else "", robust.cpu_seconds)
    return result


def batch_job(settings, records, frames, logs):
    """The series of one batch (:func:`~mcfbench.studies.matrix.plan.batches`): the
    matrix's Snakemake job. Several cheap series in one process save the start-up
    of every one but the first (importing the harness and loading the compiled
    kernels, about 1 s each) and Snakemake's work per job; a heavy series has its
    job to itself. A killed job redoes its own series only. Each series' first
    run is warmed up as every run is (:func:`mcfbench.running.run.warm_up`, once
    per scheme in the process, before the clock starts).

    Parameters
    ----------
    settings : dict
        :func:`~mcfbench.studies.matrix.plan.problem_settings`: the scheme and
        the level of each run are those of its record path, so
        that the job's params depend neither on the batch's series nor on their
        levels.
    records, frames : list of str
        The paths of every run, series after series
        (:func:`~mcfbench.studies.matrix.plan.record_path`).
    logs : list of str
        One log file per series, in the order of their records.

    Returns
    -------
    list of list of RunResult
        Per series, per level.
    """
    series = {}
    for record, frame in zip(records, frames, strict=True):
        series.setdefault(scheme_of(record), []).append((record, frame))
    if len(series) != len(logs):
        raise ValueError(f"{len(logs)} log files for the {len(series)} series "
                         f"{list(series)}: give one per series")
    return [series_job({**settings, "scheme": scheme}, [r for r, _ in runs],
                       [f for _, f in runs], log)
            for (scheme, runs), log in zip(series.items(), logs, strict=True)]


def series_job(series, records, frames, log_path=None):
    """The runs of one scheme on one problem's refinement series, coarsest first,
    each :func:`job` (its record and frames written as soon as it is done), logged
    to ``log_path``.

    ``series`` is :func:`~mcfbench.studies.matrix.plan.series_settings`; the level of
    each run is that of its record path, so that the job's params do not depend
    on the set of levels.
    """
    setup_logging(log_path)
    return [job({**series, "level": level_of(r)}, r, f)
            for r, f in zip(records, frames, strict=True)]


def robust_fields(robust):
    """The record's keys of the robust re-run (:func:`job`; None: there was none):
    ``robust_status`` (``""`` without a re-run), ``robust_solver``, ``robust_message``,
    ``robust_t_failed``, ``robust_steps_done``, ``robust_iterations`` (of the whole
    run: the failed solver's steps before the failure and the robust solver's
    after), ``robust_cpu_seconds`` (the continuation's after the failure: what the
    robust solver cost beyond the run) and ``robust_metrics`` (metric -> value, NaN
    unless it finished)."""
    if robust is None:
        return {"robust_status": ""}
    return {"robust_status": robust.status, "robust_solver": robust.solver,
            "robust_message": robust.message, "robust_t_failed": robust.t_failed,
            "robust_steps_done": robust.steps_done, "robust_iterations": robust.iterations,
            "robust_cpu_seconds": robust.cpu_seconds, "robust_metrics": dict(robust.metrics)}
