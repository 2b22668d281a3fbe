"""The benchmark matrix: every scheme on every problem over its refinement series.

One run is :func:`mcfbench.running.run.framed_run` of one (scheme, problem,
level) with the problem's own time rule and the shared solver: BiCGStab (the
paper's) on the problems with a refinement series, the robust method
(:func:`robust_method`) on the real-world-like meshes (``tau_rule =
"mesh"``). The study protocol (``workflow/rules/matrix.smk`` calls these):

* :func:`plan`: the config key ``matrix`` checked against the registries;
  :func:`run_settings`, the settings of one run;
* :func:`job`: one run with its record and first and last frames; a scheme
  that refuses the surface gives a record with status ``unsupported``;
* :func:`aggregate`: the records into the tables
  (:mod:`mcfbench.presentation.matrix_tables`);
* :func:`findings`: ``findings.md`` from the summary table only
  (:mod:`mcfbench.presentation.matrix_findings`).

The plots are in :mod:`mcfbench.presentation.matrix_plots`, the gallery of
user meshes in :mod:`mcfbench.studies.gallery`.
"""

import logging
from pathlib import Path

from mcfbench.presentation.matrix_findings import cheapest_to_reach, matrix_findings
from mcfbench.presentation.matrix_tables import (
    TIMING_NOTE,
    latex,
    long_table,
    markdown,
    problem_table,
    read_long_table,
    read_summary,
    summary_table,
    summary_views,
)
from mcfbench.running.run import framed_run
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.records import read_records
from mcfbench.studies.config import ConfigError

EXACT_SOLVER = "bicgstab"
"""Solver of the problems with a refinement series: the paper's comparison."""


# ---------------------------------------------------------------- config


def robust_method():
    """The shared solver's method for meshes of unknown quality (:data:`mcfbench.running.solver.ROBUST`)."""
    from mcfbench.running.solver import ROBUST

    return ROBUST


def is_mesh_problem(problem):
    """A mesh without a refinement series: ``tau ~ (mean edge)^2``, fixed steps
    (the robust solver)."""
    return getattr(problem, "tau_rule", "level") == "mesh"


REAL_WORLD_SURFACES = ("blobby", "implicit_torus", "perturbed_sphere", "remeshed_sphere",
                       "anisotropic_sphere", "flat_patch")
"""Surfaces of :mod:`mcfbench.geometry.surfaces` that imitate meshes from the real world."""


def is_real_world(problem):
    """A real-world-like mesh: a mesh problem or one on a surface of
    :data:`REAL_WORLD_SURFACES` (a bad mesh of a simple surface). The
    recommendation asks that a scheme does not break down on these."""
    return is_mesh_problem(problem) or getattr(problem, "surface", "") in REAL_WORLD_SURFACES


def _levels(value, key):
    if value is None:
        return None
    if not isinstance(value, (list, tuple)):
        value = [value]
    try:
        levels = sorted({int(v) for v in value})
    except (TypeError, ValueError):
        raise ConfigError(f"config key {key!r}: levels must be whole numbers, got "
                          f"{value!r}") from None
    if any(level < 1 for level in levels):
        raise ConfigError(f"config key {key!r}: levels start at 1, got {value!r}")
    return levels


def plan(section=None, schemes=None, problems=None):
    """The config key ``matrix`` checked against the registries and normalised.

    Parameters
    ----------
    section : dict, optional
        ``schemes`` ("all" or a list of :data:`mcfbench.running.schemes.SCHEMES`
        names), ``with_integrators`` (integrator -> schemes also run with it,
        as ``NAME@INTEGRATOR``), ``problems`` (problem -> levels; a problem of the registry
        not named runs at its registry levels, ``[]`` leaves it out),
        ``rtol``, ``maxiter``, ``solver`` (method of the refinement series),
        ``mesh_solver`` (method of the real-world-like meshes, ``"robust"``
        = :func:`robust_method`).
    schemes, problems : dict, optional
        The registries (default :data:`~mcfbench.running.schemes.SCHEMES`,
        :data:`~mcfbench.running.problems.PROBLEMS`).

    Returns
    -------
    dict
        ``schemes`` (list; those of ``with_integrators`` last), ``problems``
        (name -> sorted levels, registry order), ``rtol``, ``maxiter``, ``solver``, ``mesh_solver``.

    Raises
    ------
    ConfigError
        An unknown scheme, problem or solver, or bad levels, naming the key.
    """
    from mcfbench.running import solver as _solver
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import find_scheme, joined_name

    if schemes is None:
        from mcfbench.running.schemes import SCHEMES as schemes
    if problems is None:
        from mcfbench.running.problems import PROBLEMS as problems
    section = dict(section or {})
    chosen = section.get("schemes", "all")
    if chosen in ("all", None):
        chosen = list(schemes)
    elif isinstance(chosen, str):
        chosen = [chosen]
    stepped = {}                   # NAME@INTEGRATOR -> NAME
    for integrator, names in (section.get("with_integrators") or {}).items():
        if integrator not in INTEGRATORS or integrator == "euler":
            raise ConfigError(f"config key 'matrix.with_integrators': unknown integrator "
                              f"{integrator!r}; choose one of "
                              f"{', '.join(i for i in INTEGRATORS if i != 'euler')}")
        stepped.update({joined_name(name, integrator): name for name in names})
    unknown = [s for s in [*chosen, *stepped] if find_scheme(s, schemes) is None]
    if unknown:
        raise ConfigError(f"config key 'matrix.schemes': unknown scheme(s) {unknown}; the "
                          f"registry mcfbench.running.schemes.SCHEMES has {list(schemes)}, "
                          f"each also as NAME@INTEGRATOR ({', '.join(INTEGRATORS)})")
    overrides = section.get("problems") or {}
    unknown = [p for p in overrides if p not in problems]
    if unknown:
        raise ConfigError(f"config key 'matrix.problems': unknown problem(s) {unknown}; the "
                          f"registry mcfbench.running.problems.PROBLEMS has {list(problems)}")
    plan_problems = {}
    for name, problem in problems.items():
        levels = _levels(overrides[name], f"matrix.problems.{name}") if name in overrides \
            else sorted(int(v) for v in problem.levels)
        if levels:
            plan_problems[name] = levels
    if not plan_problems:
        raise ConfigError("config key 'matrix.problems': every problem is left out")
    methods = {}
    for key, default in (("solver", EXACT_SOLVER), ("mesh_solver", "robust")):
        method = section.get(key, default)
        method = robust_method() if method == "robust" else method
        if method not in _solver.METHODS:
            raise ConfigError(f"config key 'matrix.{key}': unknown solver {method!r}; choose "
                              f"one of {', '.join(_solver.METHODS)} or robust")
        methods[key] = method
    rtol = float(section.get("rtol", 1e-9))
    if not 0 < rtol < 1:
        raise ConfigError(f"config key 'matrix.rtol': must lie in (0, 1), got {rtol!r}")
    maxiter = int(section.get("maxiter", 1000))
    if maxiter < 1:
        raise ConfigError(f"config key 'matrix.maxiter': must be >= 1, got {maxiter!r}")
    # another integrator only for the schemes that are run (`schemes` may list fewer)
    chosen = [*chosen, *(s for s, name in stepped.items() if name in chosen)]
    return {"schemes": list(chosen), "problems": plan_problems, "rtol": rtol,
            "maxiter": maxiter, **methods}


def solver_method(plan, problem):
    """The method of ``problem``'s runs: robust on real-world-like meshes."""
    from mcfbench.running.problems import get_problem

    problem = get_problem(problem) if isinstance(problem, str) else problem
    return plan["mesh_solver"] if is_mesh_problem(problem) else plan["solver"]


def record_path(problem, scheme, level, root="results/matrix"):
    return f"{root}/runs/{problem}/{scheme}/level{level}.json"


def frames_path(problem, scheme, level, root="results/matrix"):
    return f"{root}/frames/{problem}/{scheme}/level{level}.npz"


def run_settings(plan, scheme, problem, level, code=""):
    """Everything that determines the record of one run of the matrix."""
    return {"study": "matrix", "scheme": scheme, "problem": problem, "level": int(level),
            "solver": {"method": solver_method(plan, problem), "rtol": plan["rtol"],
                       "maxiter": plan["maxiter"]},
            "code": code}


def planned_runs(plan, code="", root="results/matrix"):
    """``{record path: settings}`` of every run, problems then schemes then levels."""
    return {record_path(p, s, level, root): run_settings(plan, s, p, level, code)
            for p, levels in plan["problems"].items() for s in plan["schemes"]
            for level in levels}


# ---------------------------------------------------------------- one run


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
    solver = Solver(method=settings["solver"]["method"], rtol=settings["solver"]["rtol"],
                    maxiter=settings["solver"]["maxiter"])
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


def series_job(settings, records, frames, log_path=None):
    """The runs of one scheme on one problem's refinement series, coarsest first,
    each :func:`job` (its record and frames written as soon as it is done): the
    matrix's Snakemake job. One process per series instead of per run saves the
    start-up of every run but one (importing the harness and loading the compiled
    kernels, about 1 s each); a killed job redoes the whole series.
    """
    setup_logging(log_path)
    return [job(s, r, f) for s, r, f in zip(settings, records, frames, strict=True)]


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


# ---------------------------------------------------------------- tables


def problem_notes(problem, plan=None):
    """Lines under a problem's table: what it is, the exact answer, the solver."""
    from mcfbench.running.problems import get_problem

    p = get_problem(problem)
    notes = [f"Problem `{p.name}`: {p.label}. {p.description}".strip()]
    if p.exact:
        notes.append(f"Exact answer: {p.exact}.")
    if plan is not None:
        notes.append(f"Solver: {solver_method(plan, p)}, rtol {plan['rtol']:g}.")
    return notes


def write_tables(table, out_dir, plan):
    """Write ``matrix.csv``, ``{problem}.md/.tex`` and ``summary.md/.tex/.csv``."""
    from mcfbench.running.schemes import scheme_label
    from mcfbench.storage.atomic import write_text

    out = Path(out_dir)
    labels = {s: scheme_label(s) for s in plan["schemes"]}
    problems = [p for p in plan["problems"] if p in set(table["problem"])]
    write_text(out / "matrix.csv", table.to_csv(index=False, float_format="%.10g"))
    for problem in problems:
        frame, metric = problem_table(table, problem, plan["schemes"], labels)
        notes = [f"Main metric: `{metric}` per level (value, or the status of a run that "
                 f"did not finish); EOC (3.1) between consecutive levels."] + \
            problem_notes(problem, plan) + [TIMING_NOTE]
        write_text(out / f"{problem}.md", f"# Matrix: {problem}\n\n" + markdown(frame, notes))
        write_text(out / f"{problem}.tex",
                   latex(frame, f"Benchmark matrix, problem {problem}", notes))
    summary = summary_table(table, problems, plan["schemes"])
    write_text(out / "summary.csv", summary.to_csv(index=False, float_format="%.10g"))
    wide = summary_views(summary, problems, plan["schemes"], labels)
    notes = ["Each cell: the EOC (3.1) between the two finest finished levels and the "
             "finest finished level's value of the problem's main metric (in brackets "
             "after the problem), or the status and breakdown time of the coarsest run "
             "that did not finish.", TIMING_NOTE]
    write_text(out / "summary.md", "# Matrix summary\n\n" + markdown(wide, notes))
    write_text(out / "summary.tex", latex(wide, "Benchmark matrix: summary", notes))
    return summary


def aggregate(expected, plan, out_dir):
    """The records of every planned run into the long table and its views
    (:func:`write_tables`); returns ``(table, summary)``."""
    table = long_table(list(read_records(expected).values()), plan["schemes"], list(plan["problems"]))
    return table, write_tables(table, out_dir, plan)


def mesh_problems(plan):
    """The real-world-like problems of the plan (:func:`is_real_world`)."""
    from mcfbench.running.problems import get_problem

    return [p for p in plan["problems"] if is_real_world(get_problem(p))]


def findings(summary_csv, out, plan, long_csv=None):
    """``findings.md`` from ``summary.csv`` and, for the cost of accuracy, the long
    table ``matrix.csv`` (numbers from the tables only)."""
    from mcfbench.running.schemes import scheme_label
    from mcfbench.storage.atomic import write_text

    summary = read_summary(summary_csv)
    labels = {s: scheme_label(s) for s in plan["schemes"]}
    costs = cheapest_to_reach(read_long_table(long_csv)) if long_csv else ()
    text = matrix_findings(summary, labels, mesh_problems(plan),
                           source=Path(summary_csv).as_posix(), work_precision=costs)
    write_text(out, text)
    return text


def picture_runs(plan, root="results/matrix"):
    """``{(problem, scheme): (record path, frames path)}`` of the picture grid:
    the coarsest level of each problem."""
    return {(p, s): (record_path(p, s, min(levels), root), frames_path(p, s, min(levels), root))
            for p, levels in plan["problems"].items() for s in plan["schemes"]}


# ---------------------------------------------------------------- findings


# ---------------------------------------------------------------- gallery


