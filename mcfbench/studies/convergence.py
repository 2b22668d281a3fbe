"""Table 3.1 of the paper (Section 3.1): the shrinking sphere on each level, any scheme,
with the published values.

The study protocol (``workflow/rules/convergence.smk`` calls it):

* :func:`plan`: the config keys of Table 3.1 (``levels``, ``schemes``, ``rtol``,
  ``tau_level_1``, ``t_final``) checked across keys; :func:`record_settings`, the
  settings of one run record (shared with the beyond study's levels);
* :func:`job`: one scheme on one level, its record;
* :func:`aggregate`: the records into Table 3.1 (CSV, Markdown, LaTeX,
  provenance; :mod:`mcfbench.presentation.convergence_tables`).

:func:`sphere_table` is the same table computed in one process (the command
line's ``sphere-table``).
"""

import math

from mcfbench.running.problems import get_problem
from mcfbench.running.schemes import joined_name
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
    return f"results/runs/{scheme}/level{level}.json"


def record_settings(plan, scheme, level, code, *, study=None, tau=None, t_final=None,
                    rtol=None):
    """Everything that determines the run record of (scheme, level).

    ``study``, ``tau``, ``t_final`` and ``rtol`` override Table 3.1's settings
    (the studies beyond it); without them the settings, and so the hash, are
    those of Table 3.1. ``code``: :func:`mcfbench.storage.provenance.code_hash`.
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


def solver_of(settings):
    """The shared solver with the settings' tolerance (``maxiter``, ``threads`` if given)."""
    from mcfbench.running.solver import Solver

    return Solver(rtol=settings["rtol"], **{k: settings[k] for k in ("maxiter", "threads")
                                            if k in settings})


def job(settings, output, log):
    """One scheme on one level of the problem with ``settings``: its run record.

    Returns
    -------
    mcfbench.storage.records.RunResult
    """
    from mcfbench.running.run import run
    from mcfbench.storage.records import write_record

    problem = get_problem(settings["problem"]).with_settings(t_final=settings["t_final"])
    log.info("%s level %d: tau %g, t_final %g, rtol %g", settings["scheme"], settings["level"],
             settings["tau"], settings["t_final"], settings["rtol"])
    result, _ = run(settings["scheme"], problem, settings["level"], tau=settings["tau"],
                    t_final=settings["t_final"], solver=solver_of(settings),
                    threads=settings.get("threads", 1))
    record = write_record(output, result, settings)
    log.info("%s level %d: status %s, L2 error %.4e, %d iterations, %.3f s wall, "
             "%.0f MB peak memory -> %s", result.scheme, result.level, result.status,
             result.metrics.get("l2_error", math.nan), result.iterations, result.wall_seconds,
             record["peak_rss_mb"], output)
    if result.status != "ok":
        log.warning("%s", result.message)
    return result


def aggregate(expected, schemes, levels, settings, outputs, log):
    """Table 3.1 from the run records ``expected`` (path -> settings): CSV,
    Markdown, LaTeX and the provenance sidecar, written together.

    Every record is checked first (:func:`mcfbench.storage.records.read_records`);
    one bad record stops the aggregation with a message naming the file.
    ``outputs``: ``csv``, ``md``, ``tex``, ``provenance`` -> path.

    Returns
    -------
    dict
        The documents (``csv``, ``md``, ``tex``: text).
    """
    from mcfbench.presentation.convergence_tables import (
        convergence_documents,
        level_table,
    )
    from mcfbench.storage.atomic import json_text, write_files
    from mcfbench.storage.provenance import sidecar
    from mcfbench.storage.records import read_records

    records = read_records(expected, log)
    table = level_table({(r["scheme"], r["level"]): r for r in records.values()},
                        list(schemes), [int(level) for level in levels])
    docs = convergence_documents(table, list(schemes), settings)
    texts = {str(outputs[key]): docs[key] for key in ("csv", "md", "tex")}
    provenance = sidecar({"rule": "convergence_table", **settings}, records, texts)
    write_files({**texts, str(outputs["provenance"]): json_text(provenance)})
    log.info("wrote %s\n%s", ", ".join(texts), docs["md"])
    return docs


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

    from mcfbench.presentation.convergence_tables import PUBLISHED, PUBLISHED_COLUMNS
    from mcfbench.running.run import level_sweep

    table = level_sweep(scheme, "sphere", levels, **options)
    table.insert(table.columns.get_loc("iterations") + 1, "eoc", table.pop("eoc_l2_error"))
    published = pd.DataFrame.from_dict(PUBLISHED, orient="index",
                                       columns=PUBLISHED_COLUMNS)
    for column in ("l2_error", "iterations", "eoc", "cpu_seconds"):
        table[f"paper_{column}"] = table["level"].map(published[column])
    table["l2_ratio"] = table["l2_error"] / table["paper_l2_error"]
    return table
