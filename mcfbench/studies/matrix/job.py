"""One run of the benchmark matrix (:func:`job`), the series of one scheme on one
problem (:func:`series_job`, the Snakemake job) and the robust re-run of a run
that its solver failed (:func:`robust_rerun`)."""

import logging

from mcfbench.running.run import framed_run
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.matrix.plan import level_of


def job(settings, record, frames, log_path=None):
    """One run of the matrix: the record (:func:`mcfbench.storage.records.write_record`,
    with ``metric_names``) and the first and last frames (npz), both atomic.
    ``log_path``: the job's log file (set up here); None logs to the logger that
    the caller set up (:func:`series_job`, one log for a series).

    A run that ends with a ``solver_*`` status is run again with the scheme's robust
    solver (:attr:`mcfbench.running.schemes.Scheme.robust_solver`, ``direct``) at the
    same tolerance, to tell the solver's failure from the scheme's: the record gets
    :func:`robust_fields` (``robust_status`` empty when there was no re-run); the
    frames stay those of the run itself."""
    from mcfbench.running.solver import Solver
    from mcfbench.storage.frames import save_frames
    from mcfbench.storage.records import write_record

    log = setup_logging(log_path) if log_path else logging.getLogger("pipeline")
    solver = Solver.of_settings(settings)
    log.info("%s on %s level %d, solver %s", settings["scheme"], settings["problem"],
             settings["level"], solver.method)
    result, arrays = framed_run(settings["scheme"], settings["problem"], settings["level"],
                             solver=solver)
    robust = robust_rerun(settings, result, solver)
    save_frames(frames, arrays)
    write_record(record, result, settings, metric_names=list(result.metrics),
                 **robust_fields(robust))
    log.info("%s; %d/%d steps, %s, %.1f s CPU -> %s", result.status, result.steps_done,
             result.N, ", ".join(f"{k} {v:.4g}" for k, v in result.metrics.items()),
             result.cpu_seconds, record)
    if result.status != "ok":
        log.warning("%s", result.message)
    if robust is not None:
        log.info("re-run with %s: %s%s", robust.solver, robust.status,
                 f" ({robust.message})" if robust.message else "")
    return result


def series_job(series, records, frames, log_path=None):
    """The runs of one scheme on one problem's refinement series, coarsest first,
    each :func:`job` (its record and frames written as soon as it is done): the
    matrix's Snakemake job. One process per series instead of per run saves the
    start-up of every run but one (importing the harness and loading the compiled
    kernels, about 1 s each); a killed job redoes the whole series.

    ``series`` is :func:`~mcfbench.studies.matrix.plan.series_settings`; the level of
    each run is that of its record path, so that the job's params do not depend
    on the set of levels.
    """
    setup_logging(log_path)
    return [job({**series, "level": level_of(r)}, r, f)
            for r, f in zip(records, frames, strict=True)]


def robust_rerun(settings, result, solver):
    """The run of ``settings`` again with the scheme's robust solver when ``result``
    ended with a ``solver_*`` status and did not already use it; else ``None``."""
    from dataclasses import replace

    from mcfbench.running.schemes import get_scheme
    from mcfbench.storage.statuses import SOLVER_STATUSES

    scheme = get_scheme(settings["scheme"])
    if result.status not in SOLVER_STATUSES or solver.method == scheme.robust_solver:
        return None
    robust, _ = framed_run(scheme, settings["problem"], settings["level"],
                           solver=replace(solver, method=scheme.robust_solver))
    return robust


def robust_fields(robust):
    """The record's keys of the robust re-run (:func:`robust_rerun`): ``robust_status``
    (``""`` without a re-run), ``robust_solver``, ``robust_message``, ``robust_t_failed``,
    ``robust_steps_done``, ``robust_iterations``, ``robust_cpu_seconds`` and
    ``robust_metrics`` (metric -> value, NaN unless it finished)."""
    if robust is None:
        return {"robust_status": ""}
    return {"robust_status": robust.status, "robust_solver": robust.solver,
            "robust_message": robust.message, "robust_t_failed": robust.t_failed,
            "robust_steps_done": robust.steps_done, "robust_iterations": robust.iterations,
            "robust_cpu_seconds": robust.cpu_seconds, "robust_metrics": dict(robust.metrics)}
