"""Beyond Table 3.1: level 6 and beyond, the scheme variants, the long-time, time and
space studies of the sphere (``workflow/rules/beyond.smk``; config key ``beyond``).

The study protocol:

* :func:`plan`: the config key ``beyond`` checked against the registry and the
  Table 3.1 keys it builds on (:func:`mcfbench.studies.convergence.plan`);
  :func:`beyond_runs`, every record of the study with its settings;
* :func:`job`: one run of the study: the time study of one scheme
  (:func:`mcfbench.running.run.time_convergence`) or one run on one level
  (:func:`mcfbench.studies.convergence.job`);
* :func:`aggregate`: the records into the tables and the T-monitor series
  (:mod:`mcfbench.presentation.beyond_tables`);
* :func:`findings`: the verdicts from the tables only (stable schemes, the
  finest common level, the ranking), worded in ``findings.md`` by
  :mod:`mcfbench.presentation.beyond_findings` (:func:`write_findings`).
"""

import time

from mcfbench.storage.records import FIELDS
from mcfbench.studies import convergence
from mcfbench.studies.config import (
    ConfigError,
    check_rtol,
    check_schemes,
    checked_steps,
)

TIME_FIELDS = {"scheme": str, "level": int, "reference_tau": float, "t_final": float,
               "outcome": str, "message": str, "rows": list, "wall_seconds": float,
               "peak_rss_mb": float, "settings": dict, "provenance": dict, "checksum": str}
"""Key -> type of a time-study record (:func:`job`)."""


# ---------------------------------------------------------------- the plan


def plan(config, table):
    """Check ``config["beyond"]`` against the other keys and normalise it.

    Parameters
    ----------
    config : dict
        The whole config, already checked against the schema.
    table : dict
        The plan of Table 3.1 (:func:`mcfbench.studies.convergence.plan`): the
        sphere's ``tau_level_1`` and ``t_final``, ``rtol``.

    Returns
    -------
    dict
        ``levels`` (sorted ints), ``schemes``, ``finest`` (``level``,
        ``rtol`` of its runs, ``schemes``: the schemes whose rows of the
        L2/EOC table go on to that level; none by default), ``long_time`` (``level``, ``t_final``,
        ``tau``, ``schemes``), ``time_study`` (``level``, ``taus``
        (descending), ``reference_factor``, ``t_final``, ``schemes``) and
        ``space_study`` (``levels``, ``tau``, ``t_final``, ``schemes``); times
        as floats.

    Raises
    ------
    ConfigError
        An unknown scheme, a final time that is not a whole multiple of a
        time step, a scheme of ``beyond.finest`` that is not one of
        ``beyond.schemes``, or a finest level that is not above
        ``beyond.levels``; the message names the key.
    """
    beyond = config["beyond"]
    problem = convergence.problem_of(table)
    t_final = problem.t_final
    levels = sorted({int(level) for level in beyond["levels"]})
    for level in levels:
        checked_steps("'beyond.levels'", problem, problem.tau(level), t_final,
                      f"the level-{level}")
    schemes = check_schemes("beyond.schemes", beyond["schemes"])
    finest = {"level": int(beyond["finest"]["level"]),
              "rtol": check_rtol("beyond.finest.rtol",
                                 beyond["finest"].get("rtol", table["rtol"])),
              "schemes": check_schemes("beyond.finest.schemes", beyond["finest"]["schemes"])}
    if finest["schemes"]:
        _check_finest(finest, levels, schemes, problem)
    long, time_, space = beyond["long_time"], beyond["time_study"], beyond["space_study"]
    long_level, long_t = int(long["level"]), float(long["t_final"])
    checked_steps("'beyond.long_time.t_final'", problem, problem.tau(long_level), long_t,
                  f"the level-{long_level}")
    taus = sorted({float(tau) for tau in time_["taus"]}, reverse=True)
    time_t = float(time_.get("t_final", t_final))
    for tau in taus:
        checked_steps("'beyond.time_study.taus'", problem, tau, time_t, "a")
    factor = int(time_["reference_factor"])
    checked_steps("'beyond.time_study.reference_factor'", problem, taus[-1] / factor, time_t,
                  "the reference's")
    space_tau, space_t = float(space["tau"]), float(space.get("t_final", t_final))
    checked_steps("'beyond.space_study.tau'", problem, space_tau, space_t, "the")
    return {
        "levels": levels,
        "schemes": schemes,
        "finest": finest,
        "long_time": {"level": long_level, "t_final": long_t, "tau": problem.tau(long_level),
                      "schemes": check_schemes("beyond.long_time.schemes", long["schemes"])},
        "time_study": {"level": int(time_["level"]), "taus": taus, "reference_factor": factor,
                       "t_final": time_t,
                       "schemes": check_schemes("beyond.time_study.schemes",
                                                time_["schemes"])},
        "space_study": {"levels": sorted({int(level) for level in space["levels"]}),
                        "tau": space_tau, "t_final": space_t,
                        "schemes": check_schemes("beyond.space_study.schemes",
                                                 space["schemes"])},
    }


def _check_finest(finest, levels, schemes, problem):
    """``beyond.finest`` extends rows of the L2/EOC table: its schemes are some of
    ``schemes``, its level is above ``levels`` and its time step divides t_final."""
    others = [s for s in finest["schemes"] if s not in schemes]
    if others:
        raise ConfigError(f"config key 'beyond.finest.schemes': {others} not in "
                          f"'beyond.schemes' {schemes} (the finest level continues their "
                          "rows of the L2/EOC table)")
    level = finest["level"]
    if level <= levels[-1]:
        raise ConfigError(f"config key 'beyond.finest.level': {level} is not above the "
                          f"levels of 'beyond.levels' {levels}")
    checked_steps("'beyond.finest.level'", problem, problem.tau(level), problem.t_final,
                  f"the level-{level}")


def is_finest_run(config, scheme, level):
    """Whether (scheme, level) is a run of ``beyond.finest`` by the unchecked config
    (the schema's types): the one record of Table 3.1's folder whose settings need
    the beyond plan (its own ``rtol``, :func:`level_settings`)."""
    finest = config["beyond"]["finest"]
    return int(level) == int(finest["level"]) and scheme in finest["schemes"]


def used_schemes(plan):
    """Every scheme the beyond study runs, in order of first appearance."""
    names = list(plan["schemes"])
    for key in ("long_time", "time_study", "space_study"):
        names += [s for s in plan[key]["schemes"] if s not in names]
    return names


def paper_schemes(plan):
    """Schemes of the study compared with the published Table 3.1: the DDFV ones."""
    from mcfbench.running.schemes import get_scheme

    return [s for s in plan["schemes"] if get_scheme(s).family == "ddfv"]


def levels_of(plan, scheme):
    """Levels of ``scheme`` in the L2/EOC table: ``beyond.levels``, and
    ``beyond.finest.level`` for the schemes of ``beyond.finest``."""
    finest = plan["finest"]
    return plan["levels"] + ([finest["level"]] if scheme in finest["schemes"] else [])


def level_settings(plan, table, scheme, level, code):
    """Settings of the record of (scheme, level) in Table 3.1's folder: Table 3.1's
    (:func:`mcfbench.studies.convergence.record_settings`), with the tolerance of
    ``beyond.finest`` for its runs."""
    finest = plan["finest"]
    rtol = finest["rtol"] if int(level) == finest["level"] and scheme in finest["schemes"] \
        else None
    return convergence.record_settings(table, scheme, level, code, rtol=rtol)


def study_settings(plan, table, study, scheme, level, code):
    """Settings of one run of the long-time (``study = "long_time"``) or the space
    study (``"space"``)."""
    if study == "long_time":
        return convergence.record_settings(table, scheme, level, code, study=study,
                                           t_final=plan["long_time"]["t_final"])
    space = plan["space_study"]
    return convergence.record_settings(table, scheme, level, code, study=study,
                                       tau=space["tau"], t_final=space["t_final"])


def time_settings(plan, table, scheme, code):
    """Settings of the time study of one scheme."""
    study = plan["time_study"]
    return {"study": "time", "scheme": scheme, "problem": convergence.PROBLEM,
            "level": study["level"], "taus": study["taus"],
            "reference_factor": study["reference_factor"], "t_final": study["t_final"],
            "rtol": table["rtol"], "threads": table["threads"], "code": code}


def time_steps_total(plan):
    """Time steps of one time-study job: every ``tau`` and the reference run."""
    study = plan["time_study"]
    steps = sum(round(study["t_final"] / tau) for tau in study["taus"])
    return steps + round(study["t_final"] * study["reference_factor"] / study["taus"][-1])


def beyond_runs(plan, table, code):
    """``{study: {record path: settings}}`` of the beyond study (``levels``,
    ``long_time``, ``space``, ``time``)."""
    long_level = plan["long_time"]["level"]
    return {
        "levels": {convergence.run_record(s, lv): level_settings(plan, table, s, lv, code)
                   for s in plan["schemes"] for lv in levels_of(plan, s)},
        "long_time": {f"results/beyond/runs/long_time/{s}/level{long_level}.json":
                      study_settings(plan, table, "long_time", s, long_level, code)
                      for s in plan["long_time"]["schemes"]},
        "space": {f"results/beyond/runs/space/{s}/level{lv}.json":
                  study_settings(plan, table, "space", s, lv, code)
                  for s in plan["space_study"]["schemes"]
                  for lv in plan["space_study"]["levels"]},
        "time": {f"results/beyond/runs/time/{s}.json": time_settings(plan, table, s, code)
                 for s in plan["time_study"]["schemes"]},
    }


def record_fields(settings):
    """The keys and types a record of ``settings`` must have (``required`` of
    :func:`mcfbench.storage.records.read_records`): the time study's records
    have their own (:data:`TIME_FIELDS`), every other run record :data:`FIELDS`."""
    return TIME_FIELDS if settings.get("study") == "time" else FIELDS


# ---------------------------------------------------------------- the jobs


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
                                 solver=convergence.solver_of(settings),
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


# ---------------------------------------------------------------- tables and findings


def aggregate(expected, inputs, plan, settings, paper, outputs, log):
    """The tables of the study from its records, written together.

    Parameters
    ----------
    expected : dict
        Record path -> settings of every record (:func:`beyond_runs`, flattened);
        every record is checked first (:func:`mcfbench.storage.records.read_records`).
    inputs : dict
        Study (``levels``, ``long_time``, ``space``, ``time``) -> its record paths.
    plan : dict
        :func:`plan`.
    settings : dict
        The Table 3.1 keys the tables depend on (``tau_level_1``, ``t_final``, ``rtol``).
    paper : list
        :func:`paper_schemes`.
    outputs : dict
        ``<table>_<csv|md|tex>`` of ``levels``, ``stability``, ``time_convergence``,
        ``space_convergence``, and ``t_monitor`` (the T monitor at every time
        level), ``provenance`` -> path.
    """
    from mcfbench.presentation.beyond_tables import beyond_documents, beyond_tables
    from mcfbench.presentation.formats import csv_text
    from mcfbench.storage.atomic import json_text, write_files
    from mcfbench.storage.provenance import sidecar
    from mcfbench.storage.records import read_records

    records = read_records(expected, log, required=record_fields)
    tables, series = beyond_tables(inputs, records, plan, paper)
    docs = beyond_documents(tables, plan, settings, paper)
    texts = {str(outputs[f"{name}_{ext}"]): text
             for name, doc in docs.items() for ext, text in doc.items()}
    texts[str(outputs["t_monitor"])] = csv_text(series)
    provenance = sidecar({"rule": "beyond_tables", "beyond": plan, **settings}, records, texts)
    write_files({**texts, str(outputs["provenance"]): json_text(provenance)})
    log.info("wrote %d files\n%s\n%s", len(texts) + 1, docs["levels"]["md"],
             docs["stability"]["md"])


ORDER_TOLERANCE = 0.3
"""A measured order in time within this of an integrator's order counts as that order."""


def findings(levels, stability, schemes, paper, time=None, integrators=None):
    """The verdicts of the study, from its tables only.

    Parameters
    ----------
    levels, stability : pandas.DataFrame
        The level and stability tables (:func:`aggregate`).
    time, integrators : pandas.DataFrame, optional
        The time table and the integrator table
        (:func:`mcfbench.presentation.beyond_tables.integrator_table`).
    schemes : list
        The schemes of the level table (``beyond.schemes``).
    paper : list
        The schemes compared with the published Table 3.1 (:func:`paper_schemes`).

    Returns
    -------
    dict
        ``stable``: the schemes whose every run finished with no T-vertex outside
        its triangle (their runs of the stability table; of the level table for a
        scheme without T-vertices); ``variants`` and ``unstable``: the schemes of
        ``paper`` that are and are not stable; ``finest``: the finest level every
        scheme ran; ``reference``: the scheme the costs are compared with (the
        first of ``paper``, else of ``schemes``); ``ranking``: ``(scheme, L2
        error)`` of the stable ``variants`` that finished level ``finest``, most
        accurate first; ``deviations``: ``(scheme, level, L2 / published)`` of
        each stable variant's largest deviation from the published errors;
        ``time_orders``: integrator -> ``(its order, rows)``, a row per scheme of
        the time table with that integrator: ``scheme`` (without ``@``),
        ``order`` and ``volume_order`` (medians over the pairs of halved
        steps), ``pointwise`` and ``by_volume`` (within :data:`ORDER_TOLERANCE`
        of the integrator's order); ``integrators``: the rows of the integrator
        table at the finest level each (scheme, integrator) ran, as dicts.
    """
    import numpy as np

    stable = []
    for scheme in schemes:
        runs = stability[stability["scheme"] == scheme]
        if len(runs):
            outside = np.isfinite(runs["t_exit"]).any()
        else:                                   # no T-vertices: the level table's runs
            runs, outside = levels[levels["scheme"] == scheme], False
        if (runs["status"] == "ok").all() and not outside:
            stable.append(scheme)
    variants = [s for s in paper if s in stable]
    finest = int(levels.groupby("scheme")["level"].max()[schemes].min())
    rows = levels[(levels["level"] == finest) & levels["scheme"].isin(variants)]
    rows = rows[rows["status"] == "ok"].sort_values("l2_error")
    published = levels[levels["scheme"].isin(variants) & np.isfinite(levels["l2_ratio"])]
    worst = published.loc[(published["l2_ratio"] - 1).abs().groupby(published["scheme"]).idxmax()] \
        if len(published) else published
    return {"stable": stable, "variants": variants,
            "unstable": [s for s in paper if s not in stable], "finest": finest,
            "reference": paper[0] if paper else schemes[0],
            "ranking": [(r.scheme, float(r.l2_error)) for r in rows.itertuples()],
            "deviations": [(r.scheme, int(r.level), float(r.l2_ratio))
                           for r in worst.itertuples()],
            "time_orders": _time_orders(time), "integrators": _finest_comparisons(integrators)}


def _time_orders(time):
    """``time_orders`` of :func:`findings`."""
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import split_name

    verdict = {}
    if time is None:
        return verdict
    for scheme, part in time[time["status"] == "ok"].groupby("scheme", sort=False):
        base, name = split_name(scheme)
        order = INTEGRATORS[name].order
        point, volume = float(part["order"].median()), float(part["volume_order"].median())
        verdict.setdefault(name, (order, []))[1].append(
            {"scheme": base, "order": point, "volume_order": volume,
             "pointwise": abs(point - order) <= ORDER_TOLERANCE,
             "by_volume": abs(volume - order) <= ORDER_TOLERANCE})
    return verdict


def _finest_comparisons(integrators):
    """``integrators`` of :func:`findings`."""
    if integrators is None or not len(integrators):
        return []
    finest = integrators.loc[integrators.groupby(["scheme", "integrator"])["level"].idxmax()]
    return finest.to_dict("records")


def write_findings(tables, plan, paper, settings, out, log):
    """``findings.md`` from the tables only (``tables``: ``levels``, ``stability``,
    ``time``, ``space``, ``integrators`` -> CSV path; ``settings``: ``t_final``, ``tau_level_1``): the
    verdicts of :func:`findings` worded by
    :func:`mcfbench.presentation.beyond_findings.beyond_findings`."""
    import pandas as pd

    from mcfbench.presentation.beyond_findings import beyond_findings
    from mcfbench.storage.atomic import write_files

    levels, stability, time_table, space, integrators = (
        pd.read_csv(tables[key]) for key in ("levels", "stability", "time", "space",
                                             "integrators"))
    schemes, paper = list(plan["schemes"]), list(paper)
    text = beyond_findings(levels, stability, time_table, space, schemes, paper,
                           float(settings["t_final"]), float(settings["tau_level_1"]),
                           findings(levels, stability, schemes, paper, time_table,
                                    integrators))
    write_files({str(out): text})
    log.info("wrote %s", out)
    return text
