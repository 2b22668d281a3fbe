"""The plan of the beyond study: the config key ``beyond`` checked against the registry
and the Table 3.1 keys it builds on (:func:`plan`), every record of the study with
its settings (:func:`beyond_runs`)."""

from mcfbench.storage.records import FIELDS
from mcfbench.studies.beyond import RUN, TIME_RUN
from mcfbench.studies.config import (
    ConfigError,
    check_rtol,
    check_schemes,
    checked_steps,
)
from mcfbench.studies.convergence import plan as convergence

TIME_FIELDS = {"scheme": str, "level": int, "reference_tau": float, "t_final": float,
               "outcome": str, "message": str, "rows": list, "wall_seconds": float,
               "peak_rss_mb": float, "settings": dict, "provenance": dict, "checksum": str}
"""Key -> type of a time-study record (:func:`job`)."""


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
        (descending), ``reference_factor``, ``t_final``, ``rtol`` of its runs
        (default the top-level one), ``schemes``),
        ``space_study`` (``levels``, ``tau``, ``t_final``, ``schemes``) and
        ``scaling`` (``schemes``: every Euler scheme of the registry unless
        ``beyond.scaling.schemes`` lists them, ``levels``, ``fit_levels``: sorted
        ints, ``up_to``: scheme -> its finest level where it stops below
        ``levels``); times as floats.

    Raises
    ------
    ConfigError
        An unknown scheme, a final time that is not a whole multiple of a
        time step, a scheme of ``beyond.finest`` that is not one of
        ``beyond.schemes``, a finest level that is not above
        ``beyond.levels``, fit levels of ``beyond.scaling`` that are not among
        its levels, or fewer than two of them, a scheme of ``beyond.scaling.up_to``
        not in its schemes or with fewer levels than the fit takes; the message
        names the key.
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
        "scaling": _scaling(beyond["scaling"], problem),
        "finest": finest,
        "long_time": {"level": long_level, "t_final": long_t, "tau": problem.tau(long_level),
                      "schemes": check_schemes("beyond.long_time.schemes", long["schemes"])},
        "time_study": {"level": int(time_["level"]), "taus": taus, "reference_factor": factor,
                       "t_final": time_t,
                       "rtol": check_rtol("beyond.time_study.rtol",
                                          time_.get("rtol", table["rtol"])),
                       "schemes": check_schemes("beyond.time_study.schemes",
                                                time_.get("schemes", every_scheme()))},
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


def _scaling(scaling, problem):
    """``beyond.scaling`` checked: its ``schemes`` (``"all"`` or absent: every scheme of
    the registry with the paper's Euler step, :data:`mcfbench.running.schemes.SCHEMES`),
    its ``levels`` (each a whole number of steps to t_final), its ``fit_levels`` at
    least two of them."""
    from mcfbench.running.schemes import SCHEMES

    chosen = scaling.get("schemes", "all")
    schemes = list(SCHEMES) if chosen == "all" else \
        check_schemes("beyond.scaling.schemes", chosen)
    points = sorted({int(level) for level in scaling["levels"]})
    for level in points:
        checked_steps("'beyond.scaling.levels'", problem, problem.tau(level), problem.t_final,
                      f"the level-{level}")
    fit = sorted({int(level) for level in scaling["fit_levels"]})
    if len(fit) < 2 or not set(fit) <= set(points):
        raise ConfigError(f"config key 'beyond.scaling.fit_levels': {fit} must be at least two "
                          f"of 'beyond.scaling.levels' {points} (a slope needs two points)")
    up_to = {str(s): int(level) for s, level in scaling.get("up_to", {}).items()}
    others = [s for s in up_to if s not in schemes]
    if others:
        raise ConfigError(f"config key 'beyond.scaling.up_to': {others} not in "
                          f"'beyond.scaling.schemes'")
    short = {s: level for s, level in up_to.items()
             if len([lv for lv in points if lv <= level]) < len(fit)}
    if short:
        raise ConfigError(f"config key 'beyond.scaling.up_to': {short} leaves fewer than "
                          f"{len(fit)} levels of 'beyond.scaling.levels' {points} (the fit "
                          "takes as many as 'beyond.scaling.fit_levels')")
    return {"schemes": schemes, "levels": points, "fit_levels": fit, "up_to": up_to}


def scaling_levels(scaling, scheme):
    """Levels of ``scheme`` in the scaling study (``plan["scaling"]``): its ``levels``,
    up to the scheme's level of ``up_to`` (a scheme whose finest run costs too much)."""
    top = scaling["up_to"].get(scheme, scaling["levels"][-1])
    return [level for level in scaling["levels"] if level <= top]


def scaling_fit_levels(scaling, scheme):
    """Levels of the fits of ``scheme``: ``fit_levels``, or for a scheme of ``up_to``
    as many of its own finest levels (``fit_levels`` 4, 5, 6, up to 5: 3, 4, 5)."""
    if scheme not in scaling["up_to"]:
        return scaling["fit_levels"]
    return scaling_levels(scaling, scheme)[-len(scaling["fit_levels"]):]


def is_finest_run(config, scheme, level):
    """Whether (scheme, level) is a run of ``beyond.finest`` by the unchecked config
    (the schema's types): the one record of Table 3.1's folder whose settings need
    the beyond plan (its own ``rtol``, :func:`level_settings`)."""
    finest = config["beyond"]["finest"]
    return int(level) == int(finest["level"]) and scheme in finest["schemes"]


def used_schemes(plan):
    """Every scheme the beyond study runs, in order of first appearance."""
    names = list(plan["schemes"])
    for key in ("long_time", "time_study", "space_study", "scaling"):
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
            "rtol": study["rtol"], "threads": table["threads"], "code": code}


def time_steps_total(plan):
    """Time steps of one time-study job: every ``tau`` and the reference run."""
    study = plan["time_study"]
    steps = sum(round(study["t_final"] / tau) for tau in study["taus"])
    return steps + round(study["t_final"] * study["reference_factor"] / study["taus"][-1])


def beyond_runs(plan, table, code):
    """``{study: {record path: settings}}`` of the beyond study (``levels``,
    ``long_time``, ``space``, ``time``, ``scaling``: a run of both ``levels`` and
    ``scaling``, the same record, is one job)."""
    long_level = plan["long_time"]["level"]
    return {
        "levels": {convergence.run_record(s, lv): level_settings(plan, table, s, lv, code)
                   for s in plan["schemes"] for lv in levels_of(plan, s)},
        "long_time": {RUN.format(study="long_time", scheme=s, level=long_level):
                      study_settings(plan, table, "long_time", s, long_level, code)
                      for s in plan["long_time"]["schemes"]},
        "space": {RUN.format(study="space", scheme=s, level=lv):
                  study_settings(plan, table, "space", s, lv, code)
                  for s in plan["space_study"]["schemes"]
                  for lv in plan["space_study"]["levels"]},
        "time": {TIME_RUN.format(scheme=s): time_settings(plan, table, s, code)
                 for s in plan["time_study"]["schemes"]},
        "scaling": {convergence.run_record(s, lv): level_settings(plan, table, s, lv, code)
                    for s in plan["scaling"]["schemes"]
                    for lv in scaling_levels(plan["scaling"], s)},
    }


def record_fields(settings):
    """The keys and types a record of ``settings`` must have (``required`` of
    :func:`mcfbench.storage.records.read_records`): the time study's records
    have their own (:data:`TIME_FIELDS`), every other run record :data:`FIELDS`."""
    return TIME_FIELDS if settings.get("study") == "time" else FIELDS


def from_config(config, plans):
    """:func:`plan` of the config, on Table 3.1's plan (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config, plans.plan("convergence"))


def study_runs(plans):
    """:func:`beyond_runs` of the pipeline's plans."""
    return beyond_runs(plans.plan("beyond"), plans.plan("convergence"), plans.code)


TABLE_STUDIES = ("levels", "long_time", "space", "time")
"""The studies of rule ``beyond_tables``; the scaling study has its own rule
(``beyond_scaling``), so that its table needs its runs only."""


def study_records(plans, studies=TABLE_STUDIES):
    """``{record path: settings}`` of every run of ``studies`` of the beyond study."""
    runs = study_runs(plans)
    return {path: s for study in studies for path, s in runs[study].items()}


def study_run_settings(plans, study, scheme, level):
    """Settings of one run of the long-time or the space study."""
    return study_settings(plans.plan("beyond"), plans.plan("convergence"), study, scheme, level,
                          plans.code)


def time_run_settings(plans, scheme):
    """Settings of the time study of one scheme."""
    return time_settings(plans.plan("beyond"), plans.plan("convergence"), scheme, plans.code)


def every_scheme():
    """Every scheme of the registry with every time integrator (``NAME``, then
    ``NAME@bdf2``, ...; a scheme that integrates in time itself only as ``NAME``): the
    default schemes of the time study."""
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import SCHEMES, joined_name

    return [joined_name(s, i) for i in INTEGRATORS for s in SCHEMES
            if i == "euler" or not SCHEMES[s].integrates_itself]
