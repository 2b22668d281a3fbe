"""mcfbench: the benchmark harness for mean curvature flow schemes.

The neutral package between the schemes (``ddfv``, ``baselines``) and the
pipeline: the only place that imports both. Five layers, imports flowing
one way (``studies -> presentation -> storage``, ``studies -> running ->
geometry -> storage``):

``storage``
    run records, statuses, provenance, atomic writes, frame files.
``geometry``
    surfaces, mesh intake and validation, metrics, exact solutions, monitors.
``running``
    flow contract, registries, solver, driver, the one ``run``.
``presentation``
    number formats, tables, plots, pictures, the report.
``studies``
    one module per study (Table 3.1, beyond, figures, matrix, gallery) with
    the same protocol: ``plan``, ``job``, ``aggregate``, ``findings``.

plus the command line (:mod:`mcfbench.cli`) and the Snakemake glue
(:mod:`mcfbench.pipeline`).

Public API
----------
run(scheme, problem, level, ...) -> (RunResult, Trajectory)
    One scheme on one problem.
simulate(flow, steps, solver=..., ...) -> Trajectory
    The driver.
Solver(method, rtol, maxiter, threads=1)
    The shared linear solver.
SCHEMES, PROBLEMS, get_scheme(name), get_problem(name)
    The registries.
"""

import importlib

_EXPORTS = {
    "Trajectory": "running.driver", "simulate": "running.driver",
    "Flow": "running.flow", "FlowBreakdown": "running.flow",
    "STATUSES": "storage.statuses",
    "PROBLEMS": "running.problems", "get_problem": "running.problems",
    "SCHEMES": "running.schemes", "get_scheme": "running.schemes",
    "Solver": "running.solver", "SolverFailure": "running.solver",
    "RunResult": "storage.records", "run": "running.run",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name):
    """Import the public names on first use (``import mcfbench`` stays cheap)."""
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module 'mcfbench' has no attribute {name!r}")
