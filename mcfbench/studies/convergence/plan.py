"""The plan of Table 3.1: the config keys (``levels``, ``schemes``, ``rtol``,
``tau_level_1``, ``t_final``) checked across keys (:func:`plan`) and the settings
of one run record (:func:`record_settings`, shared with the beyond study's levels)."""

from mcfbench.running.problems import get_problem
from mcfbench.running.schemes import joined_name
from mcfbench.studies.convergence import RUN
from mcfbench.studies.config import (
    ConfigError,
    check_rtol,
    check_schemes,
    check_threads,
    checked_steps,
)

PROBLEM = "sphere"
"""The problem of Table 3.1 and of the beyond study."""


def plan(config):
    """The config keys of Table 3.1 checked across keys and normalised.

    Parameters
    ----------
    config : dict
        The whole config after the schema check (``--config levels=[1,2]``
        gives strings: normalised here).

    Returns
    -------
    dict
        ``levels`` (sorted ints), ``schemes`` (each scheme with every integrator
        of ``integrators``: ``NAME`` for Euler, ``NAME@INTEGRATOR`` else),
        ``rtol``, ``threads``, ``tau_level_1``, ``t_final`` (floats).

    Raises
    ------
    mcfbench.studies.config.ConfigError
        An unknown scheme or integrator, ``integrators`` without ``euler``,
        ``rtol`` outside (0, 1), ``threads`` not a whole
        number >= 1, or a ``t_final`` that is not a whole multiple of every
        level's time step; the message names the key.
    """
    schemes = check_schemes("schemes", config["schemes"])
    integrators = check_integrators(config.get("integrators", ["euler"]))
    checked = {"levels": sorted({int(level) for level in config["levels"]}),
               "schemes": [joined_name(s, i) for i in integrators for s in schemes],
               "rtol": check_rtol("rtol", config["rtol"]), "threads": check_threads(config),
               "tau_level_1": float(config["tau_level_1"]),
               "t_final": float(config["t_final"])}
    problem = problem_of(checked)
    for level in checked["levels"]:
        checked_steps("'t_final' and 'tau_level_1'", problem, problem.tau(level),
                      problem.t_final, f"the level-{level}")
    return checked


def check_integrators(names):
    """The config key ``integrators``: known names, ``euler`` among them (the paper's
    step, which the report compares with the published table).

    Raises
    ------
    mcfbench.studies.config.ConfigError
    """
    from mcfbench.running.integrators import INTEGRATORS

    names = list(names)
    unknown = [n for n in names if n not in INTEGRATORS]
    if unknown:
        raise ConfigError(f"config key 'integrators': unknown integrator(s) {unknown}; "
                          f"choose from {', '.join(INTEGRATORS)}")
    if "euler" not in names:
        raise ConfigError("config key 'integrators': must include euler, the paper's step "
                          "(the report compares its rows with the published Table 3.1)")
    return names


def problem_of(plan):
    """The problem of the plan: the sphere with its ``tau_level_1`` and ``t_final``."""
    return get_problem(PROBLEM).with_settings(tau_1=plan["tau_level_1"], t_final=plan["t_final"])


def run_record(scheme, level):
    """The record of (scheme, level), shared by Table 3.1 and the beyond study."""
    return RUN.format(scheme=scheme, level=level)


def record_settings(plan, scheme, level, code, *, study=None, tau=None, t_final=None,
                    rtol=None):
    """Everything that determines the run record of (scheme, level).

    ``study``, ``tau``, ``t_final`` and ``rtol`` override Table 3.1's settings
    (the studies beyond it); without them the settings, and so the hash, are
    those of Table 3.1. ``code``: :func:`mcfbench.running.identity.registry_identity`.
    """
    level = int(level)
    problem = problem_of(plan)
    settings = {"scheme": scheme, "problem": problem.name, "level": level,
                "tau": problem.tau(level) if tau is None else float(tau),
                "t_final": problem.t_final if t_final is None else float(t_final),
                "rtol": plan["rtol"] if rtol is None else rtol,
                "threads": plan["threads"], "code": code}
    return settings if study is None else {"study": study, **settings}


def table_settings(plan):
    """The config as far as Table 3.1 depends on it (its provenance)."""
    return {k: plan[k] for k in ("levels", "schemes", "tau_level_1", "t_final", "rtol")}


def from_config(config, plans):
    """:func:`plan` of the config (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config)


def sphere_run_settings(plans, scheme, level):
    """Settings of the record ``results/runs/{scheme}/level{level}.json``: Table
    3.1's, or for a run of ``beyond.finest`` the beyond study's (its tolerance;
    the only record of that folder that needs the beyond plan)."""
    from mcfbench.studies.beyond import plan as beyond

    if beyond.is_finest_run(plans.config, scheme, level):
        return beyond.level_settings(plans.plan("beyond"), plans.plan("convergence"), scheme,
                                     level, plans.code)
    return record_settings(plans.plan("convergence"), scheme, level, plans.code)


def table_records(plans):
    """``{record path: settings}`` of Table 3.1, schemes in config order."""
    table = plans.plan("convergence")
    return {run_record(s, lv): sphere_run_settings(plans, s, lv)
            for s in table["schemes"] for lv in table["levels"]}


def level_steps(plan, level):
    """Time steps of a run of ``level`` with Table 3.1's time step."""
    problem = problem_of(plan)
    return problem.time_steps(problem.tau(int(level)))
