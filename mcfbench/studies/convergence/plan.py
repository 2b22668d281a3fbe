"""The plan of Table 3.1: the config keys (``levels``, ``schemes``, ``rtol``,
``tau_level_1``, ``t_final``) checked across keys (:func:`plan`) and its runs' specs
(:func:`sphere_spec`, :func:`table_specs`; the beyond study's levels use the same)."""

from mcfbench.running.problems import get_problem
from mcfbench.running.schemes import joined_name
from mcfbench.studies.config import (
    ConfigError,
    check_rtol,
    check_schemes,
    check_threads,
    checked_steps,
)

SECTION = None
"""Table 3.1's keys are the config's top level: no section named ``convergence``
(:func:`mcfbench.pipeline.section_studies`)."""

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


EXACT_SOLVER = "bicgstab"
"""The paper's solver: every run of Table 3.1 and of the beyond study."""


def sphere_spec(plan, scheme, level, *, tau=None, t_final=None, rtol=None):
    """The :class:`~mcfbench.storage.run_store.RunSpec` of ``scheme`` on the sphere of
    ``level`` with Table 3.1's settings (``plan``): its time step of the level, its
    ``t_final``, BiCGStab at its ``rtol`` with the solver's default ``maxiter``, its
    ``threads``. ``tau``, ``t_final`` and ``rtol`` override them (the beyond study's
    runs); a matrix run with the same settings is the same spec."""
    from mcfbench.running.batch import spec_of
    from mcfbench.running.solver import Solver

    problem = problem_of(plan)
    return spec_of(scheme, PROBLEM, level,
                   solver={"method": EXACT_SOLVER,
                           "rtol": plan["rtol"] if rtol is None else rtol,
                           "maxiter": Solver.maxiter},
                   tau=problem.tau(int(level)) if tau is None else tau,
                   t_final=problem.t_final if t_final is None else t_final,
                   threads=plan["threads"])


def table_settings(plan):
    """The config as far as Table 3.1 depends on it (its provenance)."""
    return {k: plan[k] for k in ("levels", "schemes", "tau_level_1", "t_final", "rtol")}


def from_config(config, plans):
    """:func:`plan` of the config (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config)


def table_specs(plan):
    """``{(scheme, level): spec}`` of Table 3.1, schemes in config order."""
    return {(s, lv): sphere_spec(plan, s, lv) for s in plan["schemes"] for lv in plan["levels"]}


def run_specs(plans):
    """The specs of Table 3.1 (the run store's: :class:`mcfbench.pipeline.RunStore`)."""
    return table_specs(plans.plan("convergence")).values()
