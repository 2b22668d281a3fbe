"""The plan of the benchmark matrix: the config key ``matrix`` checked against the
registries (:func:`plan`) and the spec of every run (:func:`planned_specs`, in the run
store: :mod:`mcfbench.storage.run_store`)."""

from mcfbench.studies.config import ConfigError
from mcfbench.studies.matrix import is_mesh_problem, remeshed_name

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
    stepped.update({remeshed_name(n): n for n in section.get("with_remeshing") or ()})
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


def run_scheme(scheme, problem):
    """The scheme name a run of ``scheme`` on ``problem`` takes: ``NAME+STRATEGY`` on a
    problem whose runs take a mesh strategy (its ``mesh_strategy``: the dumbbell through
    its pinch, ``NAME+surgery``) when the name has none, else ``scheme``; the tables
    file it under ``scheme`` (:func:`matrix_scheme`)."""
    from mcfbench.running.problems import get_problem
    from mcfbench.running.scheme import parse_name

    problem = get_problem(problem) if isinstance(problem, str) else problem
    if problem.mesh_strategy == "none" or parse_name(scheme).strategy != "none":
        return scheme
    return f"{scheme}+{problem.mesh_strategy}"


def runs_on(scheme, problem):
    """Whether the matrix runs ``scheme`` on ``problem``: not when the name carries a
    mesh strategy other than the problem's own (its ``mesh_strategy``). On the dumbbell
    through its pinch every scheme runs as ``NAME+surgery``, which remeshes as
    ``+remesh`` does (:mod:`mcfbench.running.remeshing`): ``NAME+remesh`` there would
    stop at the pinch, and its scheme's row is already remeshed."""
    from mcfbench.running.problems import get_problem
    from mcfbench.running.scheme import parse_name

    own = (get_problem(problem) if isinstance(problem, str) else problem).mesh_strategy
    return own == "none" or parse_name(scheme).strategy in ("none", own)


def matrix_scheme(scheme, problem):
    """The matrix's name of a run's ``scheme`` on ``problem``: :func:`run_scheme`
    undone (``cotan+surgery`` on the dumbbell through its pinch is ``cotan``'s row)."""
    from mcfbench.running.problems import get_problem

    strategy = get_problem(problem).mesh_strategy
    suffix = f"+{strategy}"
    return scheme[:-len(suffix)] if strategy != "none" and scheme.endswith(suffix) else scheme


def matrix_spec(plan, scheme, problem, level):
    """The spec of one run: the problem's own time rule (:func:`mcfbench.running.batch.spec_of`),
    its solver (:func:`solver_method`, the plan's ``rtol`` and ``maxiter``), one
    thread, the first and the last frame; the scheme the problem's mesh strategy's
    (:func:`run_scheme`)."""
    from mcfbench.running.batch import spec_of

    return spec_of(run_scheme(scheme, problem), problem, level,
                   solver={"method": solver_method(plan, problem), "rtol": plan["rtol"],
                           "maxiter": plan["maxiter"]})


def planned_specs(plan):
    """``{(problem, scheme, level): spec}`` of every run, problems then schemes then
    levels (the schemes each problem runs: :func:`runs_on`)."""
    return {(p, s, level): matrix_spec(plan, s, p, level)
            for p, levels in plan["problems"].items() for s in plan["schemes"]
            if runs_on(s, p) for level in levels}


def picture_specs(plan):
    """``{(problem, scheme): spec}`` of the picture grid: the coarsest level of each
    problem (the schemes it runs: :func:`runs_on`)."""
    return {(p, s): matrix_spec(plan, s, p, min(levels))
            for p, levels in plan["problems"].items() for s in plan["schemes"]
            if runs_on(s, p)}


def run_specs(plans):
    """The specs of the matrix (the run store's: :class:`mcfbench.pipeline.RunStore`)."""
    return planned_specs(plans.plan("matrix")).values()


def from_config(config, plans):
    """:func:`plan` of the config (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config.get("matrix"))
