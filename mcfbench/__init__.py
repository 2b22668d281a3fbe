"""mcfbench: the benchmark harness for mean curvature flow schemes.

The neutral package between the schemes (``ddfv``, ``baselines``) and the
pipeline: the only place that imports both. It holds what every scheme
shares: the flow contract (:mod:`mcfbench.flow`), the linear solver
(:mod:`mcfbench.solver`), the driver (:mod:`mcfbench.driver`), mesh intake
and validation (:mod:`mcfbench.meshio`, :mod:`mcfbench.mesh`), surfaces
(:mod:`mcfbench.surfaces`), exact solutions, errors and metrics
(:mod:`mcfbench.errors`, :mod:`mcfbench.metrics`), the registries of
schemes and problems (:mod:`mcfbench.schemes`, :mod:`mcfbench.problems`),
the studies (:mod:`mcfbench.studies`), tables, plots, records with
provenance, and the command line (``python -m mcfbench``).

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
    "Trajectory": "driver", "simulate": "driver",
    "STATUSES": "flow", "Flow": "flow", "FlowBreakdown": "flow",
    "PROBLEMS": "problems", "get_problem": "problems",
    "SCHEMES": "schemes", "get_scheme": "schemes",
    "Solver": "solver", "SolverFailure": "solver",
    "RunResult": "studies", "run": "studies",
}
__all__ = sorted(_EXPORTS)


def __getattr__(name):
    """Import the public names on first use (``import mcfbench`` stays cheap)."""
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module 'mcfbench' has no attribute {name!r}")
