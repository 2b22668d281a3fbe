"""The plan of the benchmark matrix: the config key ``matrix`` checked against the
registries (:func:`plan`), the settings of one run (:func:`run_settings`), the
paths of its record and frames (:data:`mcfbench.studies.matrix.RECORD`) and the
Snakemake jobs that run the series, several cheap ones in one process
(:func:`batches`)."""

import re
from dataclasses import dataclass

from mcfbench.studies.config import ConfigError
from mcfbench.studies.matrix import FRAMES, RECORD, ROOT, is_mesh_problem

EXACT_SOLVER = "bicgstab"
"""Solver of the problems with a refinement series: the paper's comparison."""


def robust_method():
    """The shared solver's method for meshes of unknown quality (:data:`mcfbench.running.solver.ROBUST`)."""
    from mcfbench.running.solver import ROBUST

    return ROBUST


def _levels(value, key, first=1):
    """Sorted whole levels, none below ``first`` (the problem's first level: 0 for
    the real meshes, whose level 0 is the mesh itself, 1 for the others)."""
    if value is None:
        return None
    if not isinstance(value, (list, tuple)):
        value = [value]
    try:
        levels = sorted({int(v) for v in value})
    except (TypeError, ValueError):
        raise ConfigError(f"config key {key!r}: levels must be whole numbers, got "
                          f"{value!r}") from None
    if any(level < first for level in levels):
        raise ConfigError(f"config key {key!r}: levels start at {first}, got {value!r}")
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
        = :func:`robust_method`), ``problem_solvers`` (problem -> method, instead of
        those two for that problem's runs), ``select`` (a cut-down matrix: ``schemes``,
        exactly these, ``NAME@INTEGRATOR`` included, ``with_integrators`` then
        adds none; ``problems``, problem -> levels, exactly these; either
        omitted keeps the full matrix's).
    schemes, problems : dict, optional
        The registries (default :data:`~mcfbench.running.schemes.SCHEMES`,
        :data:`~mcfbench.running.problems.PROBLEMS`).

    Returns
    -------
    dict
        ``schemes`` (list; those of ``with_integrators`` last), ``problems``
        (name -> sorted levels, registry order), ``rtol``, ``maxiter``, ``solver``,
        ``mesh_solver``, ``problem_solvers`` (a dict, the planned problems' only: a
        cut-down matrix's rules do not depend on the others'), ``selected`` (whether
        ``select`` cut the matrix down).

    Raises
    ------
    ConfigError
        An unknown scheme, problem or solver, or bad levels, naming the key.
    """
    from mcfbench.running import solver as _solver
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import joined_name

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
    stepped.update({f"{n}+remesh": n for n in section.get("with_remeshing") or ()})  # NAME+remesh
    select = section.get("select") or {}
    if not isinstance(select, dict) or set(select) - {"schemes", "problems"}:
        raise ConfigError(f"config key 'matrix.select': a mapping with the keys schemes "
                          f"and problems, got {select!r}")
    _check_schemes([*chosen, *stepped], "matrix.schemes", schemes)
    if "schemes" in select:
        chosen, stepped = _names(select["schemes"], "matrix.select.schemes"), {}
        _check_schemes(chosen, "matrix.select.schemes", schemes)
    plan_problems = _plan_problems(section.get("problems") or {}, "matrix.problems", problems)
    if "problems" in select:
        plan_problems = _plan_problems(select["problems"], "matrix.select.problems",
                                       problems, only=True)
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
    own = section.get("problem_solvers") or {}
    if not isinstance(own, dict):
        raise ConfigError(f"config key 'matrix.problem_solvers': a mapping problem -> "
                          f"solver, got {own!r}")
    for name, method in own.items():
        if name not in problems:
            raise ConfigError(f"config key 'matrix.problem_solvers': unknown problem "
                              f"{name!r}; choose among {', '.join(problems)}")
        if method not in _solver.METHODS:
            raise ConfigError(f"config key 'matrix.problem_solvers.{name}': unknown solver "
                              f"{method!r}; choose one of {', '.join(_solver.METHODS)}")
    rtol = float(section.get("rtol", 1e-9))
    if not 0 < rtol < 1:
        raise ConfigError(f"config key 'matrix.rtol': must lie in (0, 1), got {rtol!r}")
    maxiter = int(section.get("maxiter", 1000))
    if maxiter < 1:
        raise ConfigError(f"config key 'matrix.maxiter': must be >= 1, got {maxiter!r}")
    # another integrator only for the schemes that are run (`schemes` may list fewer)
    chosen = [*chosen, *(s for s, name in stepped.items() if name in chosen)]
    return {"schemes": list(chosen), "problems": plan_problems, "rtol": rtol,
            "maxiter": maxiter, **methods,
            "problem_solvers": {p: m for p, m in own.items() if p in plan_problems},
            "selected": bool(select)}


def _names(value, key):
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, (list, tuple)) or not value:
        raise ConfigError(f"config key {key!r}: a non-empty list of scheme names, got {value!r}")
    return list(dict.fromkeys(value))


def _check_schemes(names, key, schemes):
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import find_scheme

    unknown = [s for s in names if find_scheme(s, schemes) is None]
    if unknown:
        raise ConfigError(f"config key {key!r}: unknown scheme(s) {unknown}; the "
                          f"registry mcfbench.running.schemes.SCHEMES has {list(schemes)}, "
                          f"each also as NAME@INTEGRATOR ({', '.join(INTEGRATORS)})")


def _plan_problems(levels, key, problems, only=False):
    """Problem -> sorted levels in registry order: those of ``levels``, and with
    ``only=False`` every other problem at its registry levels (``[]`` leaves one out)."""
    if not isinstance(levels, dict):
        raise ConfigError(f"config key {key!r}: a mapping problem -> levels, got {levels!r}")
    unknown = [p for p in levels if p not in problems]
    if unknown:
        raise ConfigError(f"config key {key!r}: unknown problem(s) {unknown}; the "
                          f"registry mcfbench.running.problems.PROBLEMS has {list(problems)}")
    planned = {}
    for name, problem in problems.items():
        if name in levels:
            chosen = _levels(levels[name], f"{key}.{name}", min(problem.levels))
            if only and not chosen:
                raise ConfigError(f"config key '{key}.{name}': no levels; name at least one")
        elif only:
            continue
        else:
            chosen = sorted(int(v) for v in problem.levels)
        if chosen:
            planned[name] = chosen
    return planned


def solver_method(plan, problem):
    """The method of ``problem``'s runs: its own (``problem_solvers``), else robust on
    real-world-like meshes."""
    from mcfbench.running.problems import get_problem

    problem = get_problem(problem) if isinstance(problem, str) else problem
    own = plan.get("problem_solvers", {}).get(problem.name)
    return own or (plan["mesh_solver"] if is_mesh_problem(problem) else plan["solver"])


def record_path(problem, scheme, level, root=ROOT):
    return RECORD.format(root=root, problem=problem, scheme=scheme, level=level)


def frames_path(problem, scheme, level, root=ROOT):
    return FRAMES.format(root=root, problem=problem, scheme=scheme, level=level)


def problem_settings(plan, problem, code=""):
    """What determines every record on ``problem`` but the scheme and the level: the
    params of its Snakemake jobs (:func:`batches`; each run's scheme and level are
    those of its record path), so that adding or removing levels or schemes, which
    regroups the batches, does not rerun the runs already computed."""
    return {"study": "matrix", "problem": problem,
            "solver": {"method": solver_method(plan, problem), "rtol": plan["rtol"],
                       "maxiter": plan["maxiter"]},
            "code": code}


def series_settings(plan, scheme, problem, code=""):
    """What determines every record of one scheme's series on ``problem`` but the
    level (:func:`problem_settings` and the scheme)."""
    return {**problem_settings(plan, problem, code), "scheme": scheme}


def run_settings(plan, scheme, problem, level, code=""):
    """Everything that determines the record of one run of the matrix."""
    return {**series_settings(plan, scheme, problem, code), "level": int(level)}


_RECORD_PATH = re.compile(r"/runs/[^/]+/([^/]+)/level(\d+)\.json$")
"""The scheme and the level in a record path (:data:`mcfbench.studies.matrix.RECORD`)."""


def _record_parts(record):
    """``(scheme, level)`` of a record path (:func:`record_path`)."""
    match = _RECORD_PATH.search(str(record))
    if match is None:
        raise ValueError(f"{record}: not a matrix record path "
                         f"(.../runs/<problem>/<scheme>/level<k>.json)")
    return match.group(1), int(match.group(2))


def level_of(record):
    """The level of a run from its record path (:func:`record_path`)."""
    return _record_parts(record)[1]


def scheme_of(record):
    """The scheme of a run from its record path (:func:`record_path`)."""
    return _record_parts(record)[0]


def planned_runs(plan, code="", root=ROOT):
    """``{record path: settings}`` of every run, problems then schemes then levels."""
    return {record_path(p, s, level, root): run_settings(plan, s, p, level, code)
            for p, levels in plan["problems"].items() for s in plan["schemes"]
            for level in levels}


RUN_SECONDS = 0.3
"""Estimated CPU seconds of a run besides its time steps (:func:`series_seconds`):
its mesh, its share of the scheme's warm-up, the metrics, the record and frames
written (measured 2026-11-26: a cut-down matrix of 198 runs in 8 batch jobs took
64 CPU s besides the kernels' compilation and the tables and figures: 18 s the
runs' timed flows, the other 46 s (the processes' start-up and Snakemake's work
included) 0.23 s a run)."""

BATCH_SECONDS = 60.0
"""Estimated CPU seconds of work a Snakemake job of the matrix gathers at least
(:func:`batches`). A job costs about 1.7 s besides its runs (the process's
start-up, the harness's imports, Snakemake's work; and 0.14 s a series, 0.02 s
a run: fitted to the 127 jobs of the full matrix of 2026-11-26, f699a17, their
benchmark wall times against their records' times). The jobs of that matrix
replayed on 2 cores (``benchmarks/matrix_batches.py``, the records' CPU seconds,
costliest estimate first) end the runs after 1 083 s with a 10 s budget (169
jobs), 1 009 s with 30 s (82), 984 s with 60 s (53) and 977 s with 90 s (44),
the two cores within 2 s of each other in each: 60 s takes most of the gain and
keeps a killed job's loss and a process's memory small."""

MATRIX_FACTORS = {"ddfv": 3.7, "ddfv, redistributing": 0.51, "vertex": 2.6,
                  "vertex, redistributing": 0.14, "bgn": 7.1, "kll": 2.6}
"""Kind of scheme (:func:`mcfbench.running.cost.cost_class`) -> the measured CPU
seconds of a matrix series over the cost model's estimate (:func:`series_seconds`):
the median over the series of the full matrix of 2026-11-26 (f699a17) above 0.3 s
(149, 56, 142, 20, 23, 16 series; ``benchmarks/matrix_batches.py``). The model
was fitted to steps of the sphere (:data:`mcfbench.running.cost.COSTS`); the
matrix's series take more solver iterations a step (larger steps, real meshes,
the anisotropic sphere) and the redistributing ones mostly stop early. Within a
kind, a series is still within a factor 2.5 of its measured time in the median,
a factor 7-15 in one case out of ten; the factor brings the heavy series out (1 for
a kind not measured)."""


def series_seconds(plan, scheme, problem):
    """Estimated CPU seconds of one scheme's series on ``problem``: per level,
    :data:`RUN_SECONDS` and the time steps' CPU seconds of the cost model
    (:func:`mcfbench.running.cost.estimate`; the problem's first level is built
    once per process to know its size) times the matrix's factor of the scheme's
    kind (:data:`MATRIX_FACTORS`). The order of magnitude only: it tells the heavy
    series from the cheap ones."""
    from mcfbench.running.cost import cost_class, estimate, size
    from mcfbench.running.problems import get_problem
    from mcfbench.running.schemes import get_scheme

    entry, problem = get_scheme(scheme), get_problem(problem)
    factor = MATRIX_FACTORS.get(cost_class(entry), 1.0)
    return sum(RUN_SECONDS + factor * estimate(entry, *size(entry, problem, level)).seconds
               for level in plan["problems"][problem.name])


@dataclass(frozen=True)
class Batch:
    """The series that one Snakemake job of the matrix runs in one process.

    Attributes
    ----------
    problem : str
    index : int
        Its place among the problem's batches, from 1 (the rule's name:
        :attr:`name`).
    schemes : tuple of str
        Plan order.
    seconds : float
        Their estimated CPU seconds (:func:`series_seconds`).
    """

    problem: str
    index: int
    schemes: tuple
    seconds: float

    @property
    def name(self):
        return f"{self.problem}_batch{self.index}"


def batches(plan):
    """The series of the plan gathered into Snakemake jobs: each problem's schemes
    in plan order (:func:`pack` of their :func:`series_seconds` by
    :data:`BATCH_SECONDS`), problems in plan order. Deterministic; every series in
    exactly one batch, a heavy one alone.

    Returns
    -------
    list of Batch
    """
    gathered = []
    for problem in plan["problems"]:
        seconds = {s: series_seconds(plan, s, problem) for s in plan["schemes"]}
        gathered += [Batch(problem, k, tuple(group), sum(seconds[s] for s in group))
                     for k, group in enumerate(pack(seconds, BATCH_SECONDS), start=1)]
    return gathered


def pack(costs, budget):
    """Consecutive groups of the keys of ``costs`` (in its order), each closed when its
    costs reach ``budget``; a key costing ``budget`` or more is alone.

    Parameters
    ----------
    costs : dict
        Name -> estimated cost.
    budget : float

    Returns
    -------
    list of list
        Every key in exactly one group, in order but for the heavy ones, each alone
        where it comes.
    """
    groups, group, total = [], [], 0.0
    for name, cost in costs.items():
        if cost >= budget:
            groups.append([name])
            continue
        group.append(name)
        total += cost
        if total >= budget:
            groups.append(group)
            group, total = [], 0.0
    return groups + [group] if group else groups


def picture_runs(plan, root=ROOT):
    """``{(problem, scheme): (record path, frames path)}`` of the picture grid:
    the coarsest level of each problem."""
    return {(p, s): (record_path(p, s, min(levels), root), frames_path(p, s, min(levels), root))
            for p, levels in plan["problems"].items() for s in plan["schemes"]}


def from_config(config, plans):
    """:func:`plan` of the config (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config.get("matrix"))
