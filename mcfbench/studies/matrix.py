"""The benchmark matrix: every scheme on every problem over its refinement series.

One run is :func:`mcfbench.running.run.run` of one (scheme, problem, level)
with the problem's own time rule and the shared solver: BiCGStab (the
paper's) on the problems with a refinement series, the robust method
(:func:`robust_method`) on the real-world-like meshes (``tau_rule =
"mesh"``). This module holds everything of the matrix that is not a
Snakemake rule (``workflow/rules/matrix.smk``):

* the config key ``matrix`` checked against the registries
  (:func:`matrix_plan`) and the settings of one run (:func:`run_settings`);
* one run with its record and first and last frames (:func:`run_job`);
  a scheme that refuses the surface gives a record with status
  ``unsupported`` instead of an exception;
* the long table (one row per run and metric, with the EOC (3.1) of every
  error metric between consecutive levels, :func:`long_table`), the table
  of one problem (schemes as rows, :func:`problem_table`), the summary
  (problem x scheme, :func:`summary_table`), their Markdown and LaTeX
  views, and the findings text (:func:`findings`), written from the
  numbers of those tables only;
* the gallery of user meshes (:func:`gallery_plan`, :func:`gallery_job`,
  :func:`gallery_table`).

The plots are in :mod:`mcfbench.presentation.matrix_plots`.

Errors and EOC
--------------
A metric is an *error* when its exact value is zero (:func:`is_error`:
``l2_error``, the catenoid's neck and profile errors, the height of the
hemisphere above the flat disk, the displacement of the flat patch). Its
EOC between levels ``k - 1`` and ``k`` is ``log2(|e_{k-1}| / |e_k|)``
(levels one apart, both runs finished). Other metrics (volume, area) have
no exact value: no EOC. The *main metric* of a problem
(:func:`main_metric`) is the one of the summary, the plots and the
findings.
"""

import math
import time
from pathlib import Path

import numpy as np

from mcfbench.storage.logs import setup_logging

TIMING_BASE = (
    "Timings compare schemes fairly only on the same footing: the same solver and "
    "tolerance rule, the same machine, one core each. A DDFV system has about 3 times "
    "the unknowns of a vertex-based scheme (F- and T-vertices)."
)
TIMING_NOTE = TIMING_BASE[:-1] + (
    "; the matrix uses BiCGStab on the refinement series but the robust solver on the "
    "real-world-like meshes, so compare timings within one problem only."
)
EXACT_SOLVER = "bicgstab"
"""Solver of the problems with a refinement series: the paper's comparison."""
ORDER_BAND = (1.7, 2.3)
"""An EOC in this band counts as order ~2."""
CONVERGING_EOC = 0.5
"""Below this EOC (between the two finest levels) an error is not decreasing."""
WRONG_LIMIT = 10.0
"""A non-decreasing error this many times the smallest of any scheme: a wrong limit."""
TIE = 0.05
"""Candidates whose scores differ by less than this (relative) are called tied."""
ROUNDOFF = 1e-10
"""An error at most this large on every finished level is exact up to round-off."""

# metric observer (Problem.metrics) -> preferred main metrics, best first
MAIN_METRICS = {
    "sphere_l2": ("l2_error",),
    "catenoid": ("neck_error", "max_radial_error"),
    "height": ("max_height", "l2_height"),
    "shape": ("volume", "area"),
    "still": ("max_displacement", "max_height"),
}
# metrics whose exact value is zero besides the ones named "*error*"
ZERO_METRICS = ("max_height", "l2_height", "max_displacement")
# modules that do not change what a run computes (left out of the code digest)
LONG_COLUMNS = ["scheme", "problem", "level", "h", "tau", "steps", "steps_done", "metric",
                "value", "eoc", "status", "t_failed", "min_angle", "max_flipped",
                "t_min_barycentric", "iterations", "cpu_seconds"]


class ConfigError(ValueError):
    """A value of the config key ``matrix`` or ``gallery``; the message names the key."""


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


def matrix_plan(section=None, schemes=None, problems=None):
    """The config key ``matrix`` checked against the registries and normalised.

    Parameters
    ----------
    section : dict, optional
        ``schemes`` ("all" or a list of :data:`mcfbench.running.schemes.SCHEMES`
        names), ``problems`` (problem -> levels; a problem of the registry
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
        ``schemes`` (list), ``problems`` (name -> sorted levels, registry
        order), ``rtol``, ``maxiter``, ``solver``, ``mesh_solver``.

    Raises
    ------
    ConfigError
        An unknown scheme, problem or solver, or bad levels, naming the key.
    """
    from mcfbench.running import solver as _solver

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
    unknown = [s for s in chosen if s not in schemes]
    if unknown:
        raise ConfigError(f"config key 'matrix.schemes': unknown scheme(s) {unknown}; the "
                          f"registry mcfbench.running.schemes.SCHEMES has {list(schemes)}")
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


class _Unsupported(Exception):
    """The scheme refused the surface (a ValueError of its constructor)."""


class _Guarded:
    """A scheme whose constructor's ValueError becomes :class:`_Unsupported`."""

    def __init__(self, scheme):
        self.scheme = scheme
        self.name, self.family, self.label = scheme.name, scheme.family, scheme.label

    def make(self, vertices, faces, tau, **options):
        try:
            return self.scheme.make(vertices, faces, tau, **options)
        except ValueError as err:
            raise _Unsupported(str(err)) from err


def _nan_result(scheme, problem, level, mesh, tau, steps, status, message, method, seconds):
    from mcfbench.geometry import metrics
    from mcfbench.storage.records import RunResult

    V, F = mesh
    nan = float("nan")
    return RunResult(
        scheme=scheme.name, problem=problem.name, level=int(level), nV=len(V), nF=len(V),
        nT=0, h=metrics.mean_edge_length(V, F), tau=float(tau), N=int(steps), steps_done=0,
        status=status, message=message, t_failed=0.0, t_end=0.0, steady=False, iterations=0,
        solver=method, cpu_seconds=seconds, wall_seconds=seconds, t_min_barycentric=nan,
        min_angle=nan, max_aspect=nan, max_flipped=nan, metrics={}, series={})


def run_one(scheme, problem, level, *, solver, mesh=None, tau=None):
    """:func:`mcfbench.running.run.run` with ``save_every=0``; a scheme that refuses
    the surface gives status ``unsupported`` (the initial surface as both frames).

    Returns
    -------
    result : RunResult
    frames : dict of arrays
        The trajectory's frames (first and last), ``faces``, ``steps``, ``t``.
    """
    from mcfbench.geometry.mesh import validate_mesh
    from mcfbench.running.problems import get_problem
    from mcfbench.running.run import run
    from mcfbench.running.schemes import get_scheme

    scheme = get_scheme(scheme) if isinstance(scheme, str) else scheme
    problem = get_problem(problem) if isinstance(problem, str) else problem
    start = time.process_time()
    try:
        result, traj = run(_Guarded(scheme), problem, level, solver=solver, save_every=0,
                           mesh=mesh, tau=tau)
    except _Unsupported as err:
        V, F = validate_mesh(*(problem.mesh(level) if mesh is None else mesh))
        tau = problem.tau(level, (V, F)) if tau is None else float(tau)
        steps = problem.time_steps(tau)
        result = _nan_result(scheme, problem, level, (V, F), tau, steps, "unsupported",
                             f"unsupported at step 0 (t = 0): {err}", solver.method,
                             time.process_time() - start)
        key = "F" if scheme.family == "ddfv" else "V"
        return result, {key: np.stack([V, V]), "faces": F, "steps": np.array([0, 0]),
                        "t": np.zeros(2)}
    frames = dict(traj.frames)
    frames.update(faces=traj.faces, steps=traj.steps, t=traj.t)
    return result, frames


def run_job(settings, record, frames, log_path=None):
    """One run of the matrix: the record (:func:`mcfbench.storage.records.write_record`,
    with ``metric_names``) and the first and last frames (npz), both atomic."""
    from mcfbench.running.solver import Solver
    from mcfbench.storage.atomic import save_npz
    from mcfbench.storage.records import write_record

    log = setup_logging(log_path)
    solver = Solver(method=settings["solver"]["method"], rtol=settings["solver"]["rtol"],
                    maxiter=settings["solver"]["maxiter"])
    log.info("%s on %s level %d, solver %s", settings["scheme"], settings["problem"],
             settings["level"], solver.method)
    result, arrays = run_one(settings["scheme"], settings["problem"], settings["level"],
                             solver=solver)
    save_npz(frames, **arrays)
    write_record(record, result, settings, metric_names=list(result.metrics))
    log.info("%s; %d/%d steps, %s, %.1f s CPU -> %s", result.status, result.steps_done,
             result.N, ", ".join(f"{k} {v:.4g}" for k, v in result.metrics.items()),
             result.cpu_seconds, record)
    if result.status != "ok":
        log.warning("%s", result.message)
    return result


# ---------------------------------------------------------------- tables


def is_error(metric):
    """The metric's exact value is zero (it is an error): EOC applies."""
    return "error" in metric or metric in ZERO_METRICS


def main_metric(problem, available=()):
    """The metric of ``problem`` shown in the summary, the plots and the findings.

    ``problem.main_metric`` if the problem names one, else the first of
    :data:`MAIN_METRICS` of its observers found in ``available``, else the
    first error among ``available``, else the first of ``available``.
    """
    from mcfbench.running.problems import get_problem

    problem = get_problem(problem) if isinstance(problem, str) else problem
    available = list(available)
    named = getattr(problem, "main_metric", None)
    if named and (not available or named in available):
        return named
    for observer in problem.metrics:
        for name in MAIN_METRICS.get(observer, ()):
            if name in available:
                return name
    errors = [m for m in available if is_error(m)]
    return (errors or available or [""])[0]


def _metric_names(record):
    names = record.get("metric_names")
    if names is None:
        from mcfbench.storage.records import FIELDS

        names = [k for k in record if k not in FIELDS and k != "metric_names"]
    return list(names)


def long_table(records, schemes=None, problems=None):
    """One row per run and metric (:data:`LONG_COLUMNS`), with the EOC of the errors.

    Parameters
    ----------
    records : iterable of dict
        Run records (:func:`mcfbench.storage.records.read_record`).
    schemes, problems : list of str, optional
        Row order (default: order of first appearance).

    A run without a value of a metric another run of its problem has (a
    scheme that refused the surface) gets a row with NaN.
    """
    import pandas as pd

    by_problem = {}
    for r in records:
        names = by_problem.setdefault(r["problem"], [])
        names.extend(m for m in _metric_names(r) if m not in names)
    rows = []
    for r in records:
        for metric in by_problem[r["problem"]] or [""]:
            value = r.get(metric, float("nan")) if metric else float("nan")
            rows.append({
                "scheme": r["scheme"], "problem": r["problem"], "level": int(r["level"]),
                "h": r["h"], "tau": r["tau"], "steps": int(r["N"]),
                "steps_done": int(r["steps_done"]), "metric": metric,
                "value": float("nan") if value is None else float(value), "eoc": float("nan"),
                "status": r["status"], "t_failed": r["t_failed"], "min_angle": r["min_angle"],
                "max_flipped": r["max_flipped"], "t_min_barycentric": r["t_min_barycentric"],
                "iterations": int(r["iterations"]), "cpu_seconds": r["cpu_seconds"]})
    table = pd.DataFrame(rows, columns=LONG_COLUMNS)
    for column in ("h", "tau", "value", "eoc", "t_failed", "min_angle", "max_flipped",
                   "t_min_barycentric", "cpu_seconds"):
        table[column] = table[column].astype(float)
    schemes = schemes or list(dict.fromkeys(table["scheme"]))
    problems = problems or list(dict.fromkeys(table["problem"]))
    table = _ordered(table, schemes, problems)
    return add_eoc(table)


def _ordered(table, schemes, problems):
    rank_s = {s: i for i, s in enumerate(schemes)}
    rank_p = {p: i for i, p in enumerate(problems)}
    key = table["problem"].map(rank_p).fillna(len(rank_p)).astype(int) * 10_000 + \
        table["scheme"].map(rank_s).fillna(len(rank_s)).astype(int) * 100
    order = np.lexsort([table.index.to_numpy(), table["level"].to_numpy(), key.to_numpy()])
    return table.iloc[order].reset_index(drop=True)


def add_eoc(table):
    """Fill ``eoc``: ``log2(|e_{k-1}| / |e_k|)`` for error metrics, levels one apart,
    both values finite and non-zero; NaN elsewhere."""
    table = table.copy()
    table["eoc"] = np.nan
    for (_, _, metric), group in table.groupby(["scheme", "problem", "metric"], sort=False):
        if not is_error(metric):
            continue
        group = group.sort_values("level")
        levels = group["level"].to_numpy()
        values = np.abs(group["value"].to_numpy(dtype=float))
        for i in range(1, len(group)):
            a, b = values[i - 1], values[i]
            if levels[i] - levels[i - 1] == 1 and np.isfinite(a) and np.isfinite(b) \
                    and a > 0 and b > 0:
                table.loc[group.index[i], "eoc"] = math.log2(a / b)
    return table


def _fmt(x, spec=".3e", none="–"):
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return none
    return format(x, spec)


def _levels_text(levels):
    levels = sorted(int(v) for v in levels)
    if len(levels) > 2 and levels == list(range(levels[0], levels[-1] + 1)):
        return f"{levels[0]}-{levels[-1]}"
    return ", ".join(str(v) for v in levels)


def breakdown_text(status, t_failed, level=None):
    """``"t_escaped at t = 0.052 (level 3)"``."""
    text = str(status)
    if t_failed is not None and np.isfinite(t_failed):
        text += f" at t = {t_failed:.4g}"
    if level is not None:
        text += f" (level {int(level)})"
    return text


def summary_table(table, problems=None, schemes=None):
    """Problem x scheme: EOC between the two finest finished levels and the
    finest-level value of the problem's main metric, or the breakdown.

    Returns
    -------
    pandas.DataFrame
        Columns ``problem, scheme, metric, error, levels, runs, runs_ok,
        eoc, eoc_levels, finest_level, finest_value, eocs, values, status,
        failed_level, t_failed, min_angle, t_min_barycentric,
        cpu_seconds`` (CPU of the finest finished level). ``status`` is
        ``ok`` or that of the coarsest run that did not finish; ``eocs``
        and ``values`` list every EOC and value by level (``;``-separated).
    """
    import pandas as pd

    problems = problems or list(dict.fromkeys(table["problem"]))
    schemes = schemes or list(dict.fromkeys(table["scheme"]))
    rows = []
    for problem in problems:
        part = table[table["problem"] == problem]
        if not len(part):
            continue
        metric = main_metric(problem, list(dict.fromkeys(part["metric"])))
        for scheme in schemes:
            runs = part[(part["scheme"] == scheme) & (part["metric"] == metric)] \
                .sort_values("level")
            if not len(runs):
                continue
            ok = runs[runs["status"] == "ok"]
            failed = runs[runs["status"] != "ok"]
            finished = ok[np.isfinite(ok["value"])]
            finest = finished.iloc[-1] if len(finished) else None
            eoc_rows = finished[np.isfinite(finished["eoc"])]
            last_eoc = eoc_rows.iloc[-1] if len(eoc_rows) else None
            first_fail = failed.iloc[0] if len(failed) else None
            rows.append({
                "problem": problem, "scheme": scheme, "metric": metric,
                "error": is_error(metric), "levels": _levels_text(runs["level"]),
                "runs": len(runs), "runs_ok": len(ok),
                "eoc": np.nan if last_eoc is None else last_eoc["eoc"],
                "eoc_levels": "" if last_eoc is None else
                f"{int(last_eoc['level']) - 1}-{int(last_eoc['level'])}",
                "finest_level": np.nan if finest is None else int(finest["level"]),
                "finest_value": np.nan if finest is None else finest["value"],
                "eocs": ";".join(_fmt(v, ".2f", "") for v in runs["eoc"].iloc[1:]),
                "values": ";".join(_fmt(v, ".4e", "") for v in runs["value"]),
                "status": "ok" if first_fail is None else first_fail["status"],
                "failed_level": np.nan if first_fail is None else int(first_fail["level"]),
                "t_failed": np.nan if first_fail is None else first_fail["t_failed"],
                "failed": ";".join(f"{int(r.level)}:{r.status}:{_fmt(r.t_failed, '.6g', '')}"
                                   for r in failed.itertuples()),
                "min_angle": runs["min_angle"].min(),
                "t_min_barycentric": runs["t_min_barycentric"].min(),
                "cpu_seconds": np.nan if finest is None else finest["cpu_seconds"],
            })
    return pd.DataFrame(rows)


def summary_cell(row):
    """One cell of the summary: ``"2.01 · 1.23e-03 (L4)"`` or the breakdown."""
    parts = []
    if row["error"] and np.isfinite(row["eoc"]):
        parts.append(f"EOC {row['eoc']:.2f}")
    if np.isfinite(row["finest_value"]):
        parts.append(f"{row['finest_value']:.3e} (L{int(row['finest_level'])})")
    if row["status"] != "ok":
        parts.append(breakdown_text(row["status"], row["t_failed"], row["failed_level"]))
    return "; ".join(parts) or "–"


def summary_views(summary, problems=None, schemes=None, labels=None):
    """The summary as a wide frame (problem rows, scheme columns) of cells."""
    import pandas as pd

    problems = problems or list(dict.fromkeys(summary["problem"]))
    schemes = schemes or list(dict.fromkeys(summary["scheme"]))
    labels = labels or {}
    wide = []
    for problem in problems:
        part = summary[summary["problem"] == problem]
        if not len(part):
            continue
        row = {"problem": f"{problem} ({part['metric'].iloc[0]})"}
        for scheme in schemes:
            hit = part[part["scheme"] == scheme]
            row[labels.get(scheme, scheme)] = summary_cell(hit.iloc[0]) if len(hit) else "–"
        wide.append(row)
    return pd.DataFrame(wide)


def problem_table(table, problem, schemes=None, labels=None):
    """One problem, schemes as rows: the main metric per level, its EOCs, the
    status, the mesh quality over all levels and the finest level's cost."""
    import pandas as pd

    part = table[table["problem"] == problem]
    metric = main_metric(problem, list(dict.fromkeys(part["metric"])))
    schemes = schemes or list(dict.fromkeys(part["scheme"]))
    labels = labels or {}
    levels = sorted(part["level"].unique())
    rows = []
    for scheme in schemes:
        runs = part[(part["scheme"] == scheme) & (part["metric"] == metric)] \
            .sort_values("level").set_index("level")
        if not len(runs):
            continue
        row = {"scheme": labels.get(scheme, scheme)}
        for level in levels:
            if level not in runs.index:
                row[f"L{level}"] = "–"
                continue
            r = runs.loc[level]
            row[f"L{level}"] = _fmt(r["value"]) if r["status"] == "ok" else r["status"]
        row["EOC"] = ", ".join(_fmt(v, ".2f") for v in runs["eoc"].iloc[1:]) \
            if is_error(metric) and len(runs) > 1 else "–"
        failed = runs[runs["status"] != "ok"]
        row["status"] = "ok" if not len(failed) else "; ".join(
            breakdown_text(r.status, r.t_failed, lv) for lv, r in failed.iterrows())
        finest = runs.iloc[-1]
        row["steps (finest)"] = f"{int(finest['steps_done'])}/{int(finest['steps'])}"
        row["min angle"] = _fmt(runs["min_angle"].min(), ".3g")
        row["flipped"] = _fmt(runs["max_flipped"].max(), ".0f")
        row["T monitor"] = _fmt(runs["t_min_barycentric"].min(), ".3g")
        row["iterations (finest)"] = str(int(finest["iterations"]))
        row["CPU s (finest)"] = _fmt(finest["cpu_seconds"], ".3g")
        rows.append(row)
    return pd.DataFrame(rows), metric


def markdown(frame, notes=()):
    """A pipe table (:func:`mcfbench.presentation.formats.md_table`), then ``notes`` as paragraphs."""
    from mcfbench.presentation.formats import md_table

    lines = [md_table(list(frame.columns), frame.itertuples(index=False))]
    lines += [f"\n{note}" for note in notes]
    return "\n".join(lines) + "\n"


def latex(frame, caption="", notes=()):
    """A ``table`` with a booktabs ``tabular`` (:func:`mcfbench.presentation.formats.tex_tabular`),
    the notes below it."""
    from mcfbench.presentation.formats import tex_escape, tex_tabular

    lines = [r"\begin{table}[ht]",
             tex_tabular([tex_escape(c) for c in frame.columns],
                         [[tex_escape(v) for v in row] for row in frame.itertuples(index=False)],
                         "l" + "r" * (len(frame.columns) - 1))]
    if caption:
        lines.append(r"\caption{" + tex_escape(caption) + "}")
    lines += [r"\par\smallskip{\footnotesize " + tex_escape(note) + "}" for note in notes]
    lines.append(r"\end{table}")
    return "\n".join(lines) + "\n"


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
    from mcfbench.running.schemes import SCHEMES
    from mcfbench.storage.atomic import write_text

    out = Path(out_dir)
    labels = {s: SCHEMES[s].label if s in SCHEMES else s for s in plan["schemes"]}
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


def read_runs(expected):
    """Read and check the records ``{path: settings}`` (stale or edited ones are
    refused, :func:`mcfbench.storage.records.read_record`)."""
    from mcfbench.storage.records import read_record

    return [read_record(path, settings=settings) for path, settings in expected.items()]


def aggregate(expected, plan, out_dir):
    """The records of every planned run into the long table and its views
    (:func:`write_tables`); returns ``(table, summary)``."""
    table = long_table(read_runs(expected), plan["schemes"], list(plan["problems"]))
    return table, write_tables(table, out_dir, plan)


SUMMARY_TEXT = ("levels", "eoc_levels", "eocs", "values", "failed", "metric", "status")


def read_summary(path):
    """``summary.csv`` back as written (text columns as text, empty as "")."""
    import pandas as pd

    summary = pd.read_csv(path, dtype={c: str for c in SUMMARY_TEXT})
    for column in SUMMARY_TEXT:
        summary[column] = summary[column].fillna("")
    summary["error"] = summary["error"].astype(bool)
    return summary


def read_long_table(path):
    """``matrix.csv`` back (metric names as text)."""
    import pandas as pd

    table = pd.read_csv(path, dtype={"metric": str, "status": str, "scheme": str,
                                     "problem": str})
    table["metric"] = table["metric"].fillna("")
    return table


def mesh_problems(plan):
    """The real-world-like problems of the plan (:func:`is_real_world`)."""
    from mcfbench.running.problems import get_problem

    return [p for p in plan["problems"] if is_real_world(get_problem(p))]


def write_findings(summary_csv, out, plan):
    """``findings.md`` from ``summary.csv`` (numbers from the table only)."""
    from mcfbench.running.schemes import SCHEMES
    from mcfbench.storage.atomic import write_text

    summary = read_summary(summary_csv)
    labels = {s: SCHEMES[s].label for s in plan["schemes"] if s in SCHEMES}
    text = findings(summary, labels, mesh_problems(plan),
                    source=Path(summary_csv).as_posix())
    write_text(out, text)
    return text


def load_frames(path):
    """The arrays of a frames file as a dict."""
    with np.load(path) as data:
        return {key: data[key] for key in data.files}


def picture_runs(plan, root="results/matrix"):
    """``{(problem, scheme): (record path, frames path)}`` of the picture grid:
    the coarsest level of each problem."""
    return {(p, s): (record_path(p, s, min(levels), root), frames_path(p, s, min(levels), root))
            for p, levels in plan["problems"].items() for s in plan["schemes"]}


# ---------------------------------------------------------------- findings


def _pct_or(value, metric):
    """Relative metrics (``*relative*`` or the catenoid's neck) in percent."""
    if "relative" in metric or metric.startswith("neck"):
        return f"{100 * value:+.3g} %"
    return f"{value:.3e}"


def _classify(row):
    """``order2``, ``converging``, ``not_converging``, ``exact`` (round-off),
    ``broke_down`` or ``no_error``."""
    if row["runs_ok"] < row["runs"]:
        return "broke_down"
    if not row["error"]:
        return "no_error"
    values = [abs(float(v)) for v in str(row["values"]).split(";") if v]
    if values and all(np.isfinite(v) and v <= ROUNDOFF for v in values):
        return "exact"
    if not np.isfinite(row["eoc"]):
        return "one_level" if sum(np.isfinite(v) for v in values) < 2 else "not_converging"
    if ORDER_BAND[0] <= row["eoc"] <= ORDER_BAND[1]:
        return "order2"
    return "converging" if row["eoc"] >= CONVERGING_EOC else "not_converging"


def findings(summary, labels=None, mesh_problems=(), source="tables/summary.csv"):
    """The findings, Markdown, written from the summary table only.

    Parameters
    ----------
    summary : pandas.DataFrame
        :func:`summary_table` (or ``summary.csv`` read back).
    labels : dict, optional
        Scheme name -> label.
    mesh_problems : sequence of str
        The real-world-like problems (no refinement series).
    """
    labels = labels or {}
    problems = list(dict.fromkeys(summary["problem"]))
    schemes = list(dict.fromkeys(summary["scheme"]))
    lines = ["# Findings of the benchmark matrix", "",
             f"Written by `mcfbench.studies.matrix.findings` from `{source}`: every number below "
             "is read from the tables, none typed by hand. Order ~2 means an EOC between "
             f"the two finest finished levels in [{ORDER_BAND[0]}, {ORDER_BAND[1]}]; an "
             f"error with EOC below {CONVERGING_EOC} is not decreasing.", ""]
    verdict = {}
    lines += ["## Per problem", ""]
    for problem in problems:
        part = summary[summary["problem"] == problem].copy()
        part["class"] = [_classify(r) for _, r in part.iterrows()]
        metric = part["metric"].iloc[0]
        kind = "real-world-like mesh" if problem in mesh_problems else \
            "refinement series" if part["error"].iloc[0] else "refinement series, no exact value"
        done = part[(part["runs_ok"] == part["runs"]) & np.isfinite(part["finest_value"])]
        smallest = np.abs(done["finest_value"]).min() if len(done) else np.nan
        lines += [f"### {problem}", "",
                  f"Main metric `{metric}`; levels {part['levels'].iloc[0]} ({kind}).", ""]
        for _, r in part.iterrows():
            verdict[(problem, r["scheme"])] = r
            name = f"**{r['scheme']}**"
            values = [float(v) if v else float("nan") for v in str(r["values"]).split(";")]
            shown = ", ".join(_pct_or(v, metric) if np.isfinite(v) else "–" for v in values)
            eocs = str(r["eocs"]) if isinstance(r["eocs"], str) else ""
            if r["class"] == "order2":
                text = (f"{name} converges at order ~2: EOC {r['eoc']:.2f} (levels "
                        f"{r['eoc_levels']}), finest error {_pct_or(r['finest_value'], metric)}"
                        f" (level {int(r['finest_level'])}); errors {shown}.")
            elif r["class"] == "converging":
                text = (f"{name} converges at order {r['eoc']:.2f} (levels {r['eoc_levels']}),"
                        f" not ~2; errors {shown}.")
            elif r["class"] == "not_converging":
                text = (f"{name} does not converge: the error is not decreasing (EOCs "
                        f"{eocs.replace(';', ', ') or '–'}; errors {shown})")
                ratio = abs(r["finest_value"]) / smallest if smallest > 0 else np.inf
                if ratio >= WRONG_LIMIT:
                    text += (f": it converges to another surface (finest error {ratio:.3g} x "
                             "the smallest of any scheme).")
                else:
                    text += "."
            elif r["class"] == "one_level":
                text = (f"{name}: one finished level only ({metric} {shown}), no EOC.")
            elif r["class"] == "exact":
                text = (f"{name} is exact up to round-off: {metric} at most "
                        f"{max(abs(v) for v in values):.2e} on every level.")
            elif r["class"] == "no_error":
                text = (f"{name} finished every level; {metric} at the finest level "
                        f"{r['finest_value']:.4g}.")
            else:
                fails = [f.split(":") for f in str(r["failed"]).split(";") if f]
                where = "; ".join(f"level {lv}: {st}" + (f" at t = {float(t):.4g}" if t else "")
                                  for lv, st, t in fails)
                text = (f"{name} broke down in {r['runs'] - r['runs_ok']} of {r['runs']} runs "
                        f"({where}).")
                if np.isfinite(r["finest_value"]):
                    text += (f" Finished levels: {metric} {shown}"
                             + (f", EOC {r['eoc']:.2f}" if np.isfinite(r["eoc"]) else "") + ".")
            if np.isfinite(r["t_min_barycentric"]):
                text += f" Smallest T monitor {r['t_min_barycentric']:.3g}."
            lines.append("- " + text)
        lines += _common_floor(part, metric)
        lines.append("")
    lines += recommendation(summary, verdict, problems, schemes, mesh_problems)
    return "\n".join(lines).rstrip() + "\n"


def _common_floor(part, metric):
    """A remark when no scheme's error decreases and all finish with about the
    same error: the floor belongs to the problem, not to a scheme."""
    finished = part[part["class"].isin(["not_converging", "converging"])]
    if len(finished) < 2 or (part["class"] == "order2").any() \
            or not (finished["class"] == "not_converging").all():
        return []
    values = np.abs(finished["finest_value"].to_numpy(dtype=float))
    spread = values.max() / values.min() if values.min() > 0 else np.inf
    if not spread < 2.0:
        return []
    return ["", f"No scheme's error decreases at order ~2 here, and the {len(finished)} schemes "
                f"that finished end within a factor {spread:.2f} of each other "
                f"({values.min():.3e} to {values.max():.3e}): an error floor common to all "
                "schemes (the problem's stopping rule or time error), not a property of one "
                "scheme."]


def recommendation(summary, verdict, problems, schemes, mesh_problems):
    """The section "Across problems".

    A candidate converges on every problem with an exact error (at order ~2
    wherever at least one scheme reaches order ~2 there; otherwise it only
    has to finish every level) and breaks down on none of the
    real-world-like meshes. Candidates are ranked by the geometric mean over
    those problems of their finest-level error relative to the smallest
    one. The problems without an exact value (singular flows such as a
    pinching torus) only inform: which scheme reaches the latest time.
    """
    mesh_problems = [p for p in problems if p in set(mesh_problems)]
    exact = [p for p in problems if p not in mesh_problems
             and bool(summary[summary["problem"] == p]["error"].any())]
    singular = [p for p in problems if p not in exact and p not in mesh_problems]
    lines = ["## Across problems", ""]
    if not exact:
        return lines + ["No problem with an exact error was run: no recommendation.", ""]
    lines.append(f"Problems with an exact error: {', '.join(exact)}. Real-world-like meshes "
                 f"(a breakdown disqualifies): {', '.join(mesh_problems) or 'none run'}. "
                 f"Without an exact value (breakdown times only): "
                 f"{', '.join(singular) or 'none'}.")
    lines.append("")

    def cls(p, s):
        return _classify(verdict[(p, s)]) if (p, s) in verdict else "missing"

    needs_order2 = {p: any(cls(p, s) == "order2" for s in schemes) for p in exact}
    relaxed = [p for p in exact if not needs_order2[p]]
    if relaxed:
        lines.append(f"No scheme reaches order ~2 on {', '.join(relaxed)}: there a scheme "
                     "only has to finish every level.")
        lines.append("")
    winners = {}
    for p in exact:
        good = [s for s in schemes if cls(p, s) in ("order2", "exact")] if needs_order2[p] \
            else [s for s in schemes
                  if cls(p, s) in ("converging", "not_converging", "exact", "one_level")]
        if good:
            winners[p] = min(good, key=lambda s: abs(verdict[(p, s)]["finest_value"]))
    candidates, why_not = [], {}
    for s in schemes:
        reasons = []
        for p in exact:
            c = cls(p, s)
            if c == "missing":
                reasons.append(f"not run on {p}")
            elif c == "broke_down":
                reasons.append(f"broke down on {p}")
            elif needs_order2[p] and c not in ("order2", "exact"):
                eoc = verdict[(p, s)]["eoc"]
                reasons.append(f"EOC {eoc:.2f} on {p}" if np.isfinite(eoc) else
                               f"no EOC on {p}")
        for p in mesh_problems:
            if (p, s) in verdict and cls(p, s) == "broke_down":
                reasons.append(f"broke down on {p}")
        if reasons:
            why_not[s] = reasons
        else:
            candidates.append(s)
    ratios = {}
    for p in exact:
        part = summary[(summary["problem"] == p) & np.isfinite(summary["finest_value"])
                       & (summary["runs_ok"] == summary["runs"])]
        best = np.abs(part["finest_value"]).min() if len(part) else np.nan
        if not best > ROUNDOFF:  # exact to round-off somewhere: no ranking by this problem
            continue
        for _, r in part.iterrows():
            ratios[(p, r["scheme"])] = abs(r["finest_value"]) / best

    def geometric_mean(s):
        logs = [np.log(ratios[(p, s)]) for p in exact if (p, s) in ratios]
        return float(np.exp(np.mean(logs))) if logs else float("nan")

    if candidates:
        score = {s: geometric_mean(s) for s in candidates}
        ranked = sorted(candidates, key=lambda s: (not np.isfinite(score[s]), score[s]))
        best = ranked[0]
        lines.append("Converge as required on every problem with an exact error and do not "
                     "break down on the real-world-like meshes: " + ", ".join(
                         f"{s} (finest-level errors {score[s]:.3g} x the smallest, geometric "
                         "mean)" for s in ranked) + ".")
        lines.append("")
        tied = [s for s in ranked[1:] if score[s] <= (1 + TIE) * score[best]]
        if tied:
            lines.append(f"{best} and {', '.join(tied)} are practically tied (scores within "
                         f"{100 * TIE:.0f} %): either is a sound choice.")
            lines.append("")
        beaten = [f"{p}: {winners[p]}" for p in exact if winners.get(p) not in (None, best)]
        lines.append(f"**Recommendation: {best}**" + (
            ", with the smallest finest-level error on every problem with an exact error."
            if not beaten else
            ", the smallest finest-level errors on average among them, though not on every "
            "problem (smallest elsewhere: " + "; ".join(beaten) + ")."))
    else:
        lines.append("**No scheme wins everywhere**: none converges as required on every "
                     "problem with an exact error without breaking down on a real-world-like "
                     "mesh.")
    lines.append("")
    lines.append("Smallest finest-level error per problem (among the schemes that converge as "
                 "required there): " + "; ".join(f"{p}: {winners.get(p, 'none')}"
                                                 for p in exact) + ".")
    if why_not:
        lines.append("")
        lines.append("Left out: " + "; ".join(f"{s} ({', '.join(r)})"
                                              for s, r in why_not.items()) + ".")
    if singular:
        lines.append("")
        for p in singular:
            done = [s for s in schemes if (p, s) in verdict and cls(p, s) != "broke_down"]
            times = {s: verdict[(p, s)]["t_failed"] for s in schemes if (p, s) in verdict
                     and cls(p, s) == "broke_down" and np.isfinite(verdict[(p, s)]["t_failed"])}
            text = f"On {p} "
            text += (f"{', '.join(done)} finished every level" if done else
                     "every scheme broke down")
            if times:
                latest = max(times, key=times.get)
                text += ("; " if done else ", ") + f"the latest breakdown: {latest} at t = " \
                    f"{times[latest]:.4g} (earliest: {min(times, key=times.get)} at t = " \
                    f"{min(times.values()):.4g}; coarsest failing level)"
            lines.append(text + ".")
    return lines + [""]


# ---------------------------------------------------------------- gallery

GALLERY_SURFACES = REAL_WORLD_SURFACES
"""Surfaces of the built-in gallery when the registry has no real-world-like problem."""
MESH_SUFFIXES = (".obj", ".off", ".ply", ".stl")


def gallery_plan(section=None, meshes=None, schemes=None):
    """The config key ``gallery`` (and ``meshes``) checked and normalised.

    Parameters
    ----------
    section : dict
        ``C`` (tau = C (mean edge)^2), ``steps``, ``solver`` (a method or
        ``"robust"``), ``rtol``, ``maxiter``, ``schemes`` ("all" or names).
    meshes : str, optional
        A folder of mesh files; None: the suite's own meshes
        (:func:`generated_meshes`) under ``results/gallery/meshes``.

    Returns
    -------
    dict
        ``C, steps, solver, rtol, maxiter, schemes, meshes`` (file name ->
        path), ``generated`` (file name -> (surface or problem, params)).
    """
    from mcfbench.running import solver as _solver

    if schemes is None:
        from mcfbench.running.schemes import SCHEMES as schemes
    section = dict(section or {})
    chosen = section.get("schemes", "all")
    chosen = list(schemes) if chosen in ("all", None) else \
        [chosen] if isinstance(chosen, str) else list(chosen)
    unknown = [s for s in chosen if s not in schemes]
    if unknown:
        raise ConfigError(f"config key 'gallery.schemes': unknown scheme(s) {unknown}; the "
                          f"registry mcfbench.running.schemes.SCHEMES has {list(schemes)}")
    method = section.get("solver", "robust")
    method = robust_method() if method == "robust" else method
    if method not in _solver.METHODS:
        raise ConfigError(f"config key 'gallery.solver': unknown solver {method!r}; choose one "
                          f"of {', '.join(_solver.METHODS)} or robust")
    C, steps = float(section.get("C", 0.1)), int(section.get("steps", 40))
    if not C > 0:
        raise ConfigError(f"config key 'gallery.C': must be > 0, got {C!r}")
    if steps < 1:
        raise ConfigError(f"config key 'gallery.steps': must be >= 1, got {steps!r}")
    plan = {"C": C, "steps": steps, "solver": method,
            "rtol": float(section.get("rtol", 1e-9)),
            "maxiter": int(section.get("maxiter", 1000)), "schemes": chosen}
    if meshes:
        folder = Path(meshes)
        if not folder.is_dir():
            raise ConfigError(f"config key 'meshes': {folder} is not a folder")
        files = sorted(p for p in folder.iterdir()
                       if p.is_file() and p.suffix.lower() in MESH_SUFFIXES)
        if not files:
            raise ConfigError(f"config key 'meshes': no mesh file "
                              f"({' '.join(MESH_SUFFIXES)}) in {folder}")
        plan["meshes"] = {p.name: str(p) for p in files}
        plan["generated"] = {}
    else:
        generated = generated_meshes()
        plan["meshes"] = {name: f"results/gallery/meshes/{name}" for name in generated}
        plan["generated"] = generated
    return plan


def generated_meshes():
    """``{file name: (kind, name, level)}`` of the built-in gallery: the
    real-world-like problems of the registry (:func:`is_real_world`) at the
    middle level of their refinement series, or (when there are none) the surfaces
    :data:`GALLERY_SURFACES` at their defaults."""
    from mcfbench.geometry.surfaces import SURFACES
    from mcfbench.running.problems import PROBLEMS

    mesh_problems = [p for p in PROBLEMS.values() if is_real_world(p)]
    if mesh_problems:
        return {f"{p.name}.obj": ("problem", p.name, int(sorted(p.levels)[len(p.levels) // 2]))
                for p in mesh_problems}
    return {f"{s}.obj": ("surface", s, 0) for s in GALLERY_SURFACES if s in SURFACES}


def write_obj(path, vertices, faces):
    """A triangle mesh as Wavefront OBJ (atomic, 17 significant digits)."""
    from mcfbench.storage.atomic import write_text

    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(vertices, float).tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces, int).tolist()]
    write_text(path, "\n".join(lines) + "\n")


def write_generated_mesh(entry, path):
    """Write one mesh of :func:`generated_meshes` (``entry`` = its value)."""
    from mcfbench.geometry.surfaces import make_surface
    from mcfbench.running.problems import get_problem

    kind, name, level = entry
    V, F = get_problem(name).mesh(level) if kind == "problem" else make_surface(name)
    write_obj(path, V, F)


def _gallery_problem(C, steps):
    from mcfbench.running.problems import Problem

    return Problem("gallery", "a user's mesh", "", lambda level: {}, levels=(1,), tau_1=C,
                   t_final=1.0, metrics=(), tau_rule="mesh", steps=int(steps),
                   exact="none (mesh quality and breakdown only)")


def gallery_job(mesh_path, scheme, settings, record, frames, log_path=None):
    """One scheme on one mesh file: ``tau = C h^2``, ``steps`` steps; record and
    first and last frames. A file the reader refuses gives status
    ``unsupported`` with the reader's message."""
    from mcfbench.geometry import metrics
    from mcfbench.geometry.mesh_files import read_mesh
    from mcfbench.running.schemes import get_scheme
    from mcfbench.running.solver import Solver
    from mcfbench.storage.atomic import save_npz
    from mcfbench.storage.records import write_record

    log = setup_logging(log_path)
    solver = Solver(method=settings["solver"], rtol=settings["rtol"],
                    maxiter=settings["maxiter"])
    problem = _gallery_problem(settings["C"], settings["steps"])
    scheme = get_scheme(scheme)
    extra = {"mesh": Path(mesh_path).name}
    try:
        V, F, report = read_mesh(mesh_path)
    except ValueError as err:
        log.warning("%s", err)
        result = None
        message = f"unsupported at step 0 (t = 0): the mesh was refused: {err}"
    else:
        extra["intake"] = report.notes()
        tau = settings["C"] * metrics.mean_edge_length(V, F) ** 2
        log.info("%s on %s: %d vertices, %d triangles, tau %.3g, %d steps, solver %s",
                 scheme.name, mesh_path, len(V), len(F), tau, settings["steps"], solver.method)
        result, arrays = run_one(scheme, problem, 1, solver=solver, mesh=(V, F), tau=tau)
        save_npz(frames, **arrays)
    if result is None:
        from mcfbench.storage.records import RunResult

        nan = float("nan")
        result = RunResult(scheme=scheme.name, problem="gallery", level=1, nV=0, nF=0, nT=0,
                           h=nan, tau=nan, N=settings["steps"], steps_done=0,
                           status="unsupported", message=message, t_failed=0.0, t_end=0.0,
                           steady=False, iterations=0, solver=solver.method, cpu_seconds=0.0,
                           wall_seconds=0.0, t_min_barycentric=nan, min_angle=nan,
                           max_aspect=nan, max_flipped=nan)
        save_npz(frames, faces=np.zeros((0, 3), int), steps=np.zeros(0, int), t=np.zeros(0))
    write_record(record, result, settings, metric_names=[], **extra)
    log.info("%s: %s, %d/%d steps", scheme.name, result.status, result.steps_done, result.N)
    return result


GALLERY_COLUMNS = ["mesh", "scheme", "status", "steps_done", "steps", "t_failed", "min_angle",
                   "max_flipped", "t_min_barycentric", "cpu_seconds", "vertices",
                   "triangles", "h", "tau", "solver", "message"]


def gallery_table(records):
    """Mesh x scheme: one row per record (:data:`GALLERY_COLUMNS`)."""
    import pandas as pd

    rows = [{"mesh": r["mesh"], "scheme": r["scheme"], "status": r["status"],
             "steps_done": int(r["steps_done"]), "steps": int(r["N"]),
             "t_failed": r["t_failed"], "min_angle": r["min_angle"],
             "max_flipped": r["max_flipped"], "t_min_barycentric": r["t_min_barycentric"],
             "cpu_seconds": r["cpu_seconds"], "vertices": int(r["nF"]),
             "triangles": int(r["nT"]) if r["nT"] else np.nan, "h": r["h"], "tau": r["tau"],
             "solver": r["solver"], "message": r["message"]} for r in records]
    return pd.DataFrame(rows, columns=GALLERY_COLUMNS)


def gallery_markdown(table, plan):
    """The gallery table as Markdown: mesh x scheme, with the settings and timing note."""
    import pandas as pd

    view = pd.DataFrame({
        "mesh": table["mesh"], "scheme": table["scheme"], "status": table["status"],
        "steps": [f"{a}/{b}" for a, b in zip(table["steps_done"], table["steps"])],
        "breakdown t": [_fmt(v, ".4g") for v in table["t_failed"]],
        "min angle": [_fmt(v, ".3g") for v in table["min_angle"]],
        "flipped": [_fmt(v, ".0f") for v in table["max_flipped"]],
        "T monitor": [_fmt(v, ".3g") for v in table["t_min_barycentric"]],
        "CPU s": [_fmt(v, ".3g") for v in table["cpu_seconds"]]})
    notes = [f"Every scheme on every mesh: tau = C (mean edge length)^2 with C = {plan['C']:g}, "
             f"{plan['steps']} steps, solver {plan['solver']} (rtol {plan['rtol']:g}). "
             "Min angle and flipped triangles: worst over the sampled time levels; "
             "T monitor: smallest barycentric coordinate of a T-vertex (DDFV only).",
             TIMING_BASE]
    return "# Gallery\n\n" + markdown(view, notes)
