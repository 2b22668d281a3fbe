"""One scheme on one level of Table 3.1 (:func:`job`, its run record), and the whole
table computed in one process (:func:`sphere_table`, the command line's ``sphere-table``)."""

import math

from mcfbench.running.problems import get_problem


def job(settings, output, log):
    """One scheme on one level of the problem with ``settings``: its run record.

    Returns
    -------
    mcfbench.storage.records.RunResult
    """
    from mcfbench.running.run import run
    from mcfbench.running.solver import Solver
    from mcfbench.storage.records import write_record

    problem = get_problem(settings["problem"]).with_settings(t_final=settings["t_final"])
    log.info("%s level %d: tau %g, t_final %g, rtol %g", settings["scheme"], settings["level"],
             settings["tau"], settings["t_final"], settings["rtol"])
    result, _ = run(settings["scheme"], problem, settings["level"], tau=settings["tau"],
                    t_final=settings["t_final"], solver=Solver.of_settings(settings),
                    threads=settings.get("threads", 1))
    record = write_record(output, result, settings)
    log.info("%s level %d: status %s, L2 error %.4e, %d iterations, %.3f s wall, "
             "%.0f MB peak memory -> %s", result.scheme, result.level, result.status,
             result.metrics.get("l2_error", math.nan), result.iterations, result.wall_seconds,
             record["peak_rss_mb"], output)
    if result.status != "ok":
        log.warning("%s", result.message)
    return result


def sphere_table(levels, scheme="ddfv", **options):
    """Table 3.1: the problem ``sphere`` on each level, EOC and published values.

    Parameters
    ----------
    levels : sequence of int
    scheme : str
        A name of :data:`mcfbench.running.schemes.SCHEMES`.
    **options
        Passed to :func:`mcfbench.running.run.run` (``solver``, scheme options).

    Returns
    -------
    pandas.DataFrame
        One row per level: the fields of :class:`mcfbench.storage.records.RunResult`,
        ``eoc`` (3.1) against the previous level when that is one coarser,
        and the published values as ``paper_*`` with ``l2_ratio = l2_error /
        paper_l2_error``.
    """
    import pandas as pd

    from mcfbench.running.run import level_sweep
    from mcfbench.studies.convergence.tables import PUBLISHED, PUBLISHED_COLUMNS

    table = level_sweep(scheme, "sphere", levels, **options)
    table.insert(table.columns.get_loc("iterations") + 1, "eoc", table.pop("eoc_l2_error"))
    published = pd.DataFrame.from_dict(PUBLISHED, orient="index",
                                       columns=PUBLISHED_COLUMNS)
    for column in ("l2_error", "iterations", "eoc", "cpu_seconds"):
        table[f"paper_{column}"] = table["level"].map(published[column])
    table["l2_ratio"] = table["l2_error"] / table["paper_l2_error"]
    return table
