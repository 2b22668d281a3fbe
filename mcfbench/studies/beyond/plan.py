"""The plan of the beyond study: the config key ``beyond`` checked against the registry
and the Table 3.1 keys it builds on (:func:`plan`), the spec of every run of the
study (:func:`beyond_specs`, in the run store: :mod:`mcfbench.storage.run_store`)."""

from mcfbench.studies.config import (
    ConfigError,
    check_rtol,
    check_schemes,
    checked_steps,
)
from mcfbench.studies.convergence import plan as convergence


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


def level_spec(plan, table, scheme, level):
    """The spec of (scheme, level) of the levels and the scaling studies: Table 3.1's
    (:func:`mcfbench.studies.convergence.plan.sphere_spec`, the same run), with the
    tolerance of ``beyond.finest`` for its runs."""
    finest = plan["finest"]
    rtol = finest["rtol"] if int(level) == finest["level"] and scheme in finest["schemes"] \
        else None
    return convergence.sphere_spec(table, scheme, level, rtol=rtol)


def time_taus(plan):
    """The time steps of the time study: ``taus`` and the reference's, the smallest over
    ``reference_factor``."""
    study = plan["time_study"]
    return [*study["taus"], study["taus"][-1] / study["reference_factor"]]


def beyond_specs(plan, table):
    """``{study: {key: spec}}`` of the beyond study: ``levels`` and ``scaling``
    ((scheme, level): the runs of Table 3.1's settings), ``long_time`` and ``space``
    ((scheme, level)), ``time`` ((scheme, tau), the reference's tau last)."""
    long, space, time_ = plan["long_time"], plan["space_study"], plan["time_study"]
    return {
        "levels": {(s, lv): level_spec(plan, table, s, lv)
                   for s in plan["schemes"] for lv in levels_of(plan, s)},
        "long_time": {(s, long["level"]): convergence.sphere_spec(
            table, s, long["level"], t_final=long["t_final"]) for s in long["schemes"]},
        "space": {(s, lv): convergence.sphere_spec(table, s, lv, tau=space["tau"],
                                                   t_final=space["t_final"])
                  for s in space["schemes"] for lv in space["levels"]},
        "time": {(s, tau): convergence.sphere_spec(table, s, time_["level"], tau=tau,
                                                   t_final=time_["t_final"],
                                                   rtol=time_["rtol"])
                 for s in time_["schemes"] for tau in time_taus(plan)},
        "scaling": {(s, lv): level_spec(plan, table, s, lv)
                    for s in plan["scaling"]["schemes"]
                    for lv in scaling_levels(plan["scaling"], s)},
    }


def from_config(config, plans):
    """:func:`plan` of the config, on Table 3.1's plan (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config, plans.plan("convergence"))


def study_specs(plans):
    """:func:`beyond_specs` of the pipeline's plans."""
    return beyond_specs(plans.plan("beyond"), plans.plan("convergence"))


def run_specs(plans):
    """Every spec of the beyond study (the run store's: :class:`mcfbench.pipeline.RunStore`)."""
    return list(dict.fromkeys(spec for specs in study_specs(plans).values()
                              for spec in specs.values()))


TABLE_STUDIES = ("levels", "long_time", "space", "time")
"""The studies of rule ``beyond_tables``; the scaling study has its own rule
(``beyond_scaling``), so that its table needs its runs only."""


def every_scheme():
    """Every scheme of the registry with every time integrator (``NAME``, then
    ``NAME@bdf2``, ...; a scheme that integrates in time itself only as ``NAME``): the
    default schemes of the time study."""
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import SCHEMES, joined_name

    return [joined_name(s, i) for i in INTEGRATORS for s in SCHEMES
            if i == "euler" or not SCHEMES[s].integrates_itself]
