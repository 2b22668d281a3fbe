"""The jobs of the beyond study: one scheme on one level (Table 3.1's job) or the
time study of one scheme (:func:`time_job`)."""

import time

from mcfbench.studies.convergence import job as convergence


def job(settings, output, log):
    """One run of the study: the time study of one scheme (``settings["study"] ==
    "time"``, :func:`time_job`), else one scheme on one level
    (:func:`mcfbench.studies.convergence.job`)."""
    if settings.get("study") == "time":
        return time_job(settings, output, log)
    return convergence.job(settings, output, log)


def time_job(settings, output, log):
    """Time convergence of one scheme on one mesh (:func:`mcfbench.running.run.time_convergence`).

    A reference run that breaks down does not fail the job: the record has
    ``outcome = "reference_failed"``, the message and no rows; single runs
    that break down are rows with their status.
    """
    from mcfbench.running.problems import get_problem
    from mcfbench.running.run import time_convergence
    from mcfbench.running.solver import Solver
    from mcfbench.storage.records import write_record

    problem = get_problem(settings["problem"]).with_settings(t_final=settings["t_final"])
    taus, factor = settings["taus"], settings["reference_factor"]
    log.info("%s level %d: time_convergence(taus=%s, reference_factor=%d, t_final=%g, "
             "rtol=%g)", settings["scheme"], settings["level"], taus, factor,
             settings["t_final"], settings["rtol"])
    wall = time.perf_counter()
    try:
        table = time_convergence(settings["scheme"], problem, settings["level"], taus,
                                 reference_factor=factor, t_final=settings["t_final"],
                                 solver=Solver.of_settings(settings),
                                 threads=settings.get("threads", 1))
        rows, outcome, message = table.to_dict("records"), "ok", ""
    except RuntimeError as err:
        rows, outcome, message = [], "reference_failed", str(err)
    wall = time.perf_counter() - wall
    record = write_record(output, {"scheme": settings["scheme"], "level": settings["level"],
                                   "taus": taus, "reference_factor": factor,
                                   "reference_tau": min(taus) / factor,
                                   "t_final": settings["t_final"], "outcome": outcome,
                                   "message": message, "rows": rows, "wall_seconds": wall},
                          settings)
    log.info("%s: %s in %.1f s, %.0f MB peak memory -> %s", settings["scheme"], outcome, wall,
             record["peak_rss_mb"], output)
    if outcome != "ok":
        log.warning("%s", message)
    for row in rows:
        log.info("tau %-10g error %.4e eoc %.3f %s", row["tau"], row["error"], row["eoc"],
                 row["status"])
