"""The cost of a run before it runs: peak memory and CPU time from the number of
unknowns, and the size guard of :func:`mcfbench.running.run.run`.

Measured scaling
----------------
``benchmarks/bench_cost.py`` ran the sphere at levels 2-5 (n = 162 to 10242
mesh vertices) with ``cotan``, ``cotan-redistribute``, ``ddfv``,
``ddfv-chord-redistribute-carried`` and ``bgn``, each run in a fresh process on
one core (2026-11-25, load average 11 on 2 cores), and fitted per kind of
scheme (:data:`COSTS`: vertex, DDFV, BGN, the redistributing ones apart, whose
potential is a sparse LU at every step: level 5, 29.9 MB and 78 ms a step for
``cotan-redistribute`` against 14.1 MB and 3 ms for ``cotan``; 85.7 MB and
38 ms for ``ddfv-chord-redistribute-carried`` against 27.1 MB and 6 ms for
``ddfv``; ``bgn`` 16.4 MB and 4 ms; ``kll``, its 7n x 7n system solved by
blocks (one n x n matrix for four right-hand sides), refitted 2026-11-26 beside
``cotan`` and ``bgn`` at load average 13-15: 17.0 MB and 4.4 ms against 13.8 MB
and 3.5 ms for ``cotan``, 16.3 MB and 6.3 ms for ``bgn``; a second run beside
``cotan``, 17.0 MB and 6.0 ms against 14.1 MB and 2.6 ms; before the block
solve it took 25.4 MB and 6.7 ms).

Refitted 2026-12-07 (memory is load-independent; load average 0.6-8): the level-8
sphere and a 1 024 000-vertex mesh (``benchmarks/bench_scaling.py``) had put
``dual-mdr``'s peak at 2.4 x its estimate (3.6 and 5.5 GB against 1.5 and 2.3 GB)
and ``deturck``'s at 1.06 x. ``bench_cost.py --levels 2 3 4 5`` (and ``--levels 4
5`` for the others) on every scheme, at level 5: cotan, ``cmcf``, ``cotan-voronoi``
15.6-15.7 MB; ``mdr`` 20.5, ``bgn-bdf2`` 21.5, ``cotan-intrinsic`` 22.6, ``deturck``
23.4 MB; ``dual-mdr`` 67.4 MB (its ``(X, R)`` block system: twice the unknowns, and its
Krylov vectors) and 13.8 ms a step;
``ddfv`` 30.8 MB, ``ddfv-chord-carried`` 33.8 MB; ``ddfv-chord-bgn-carried`` and
``ddfv-chord-mdr-carried`` 69.2 and 69.0 MB (the kept factors of their tangential
motions) and 16.1 and 11.9 ms; the fixed part 110-127 MB (168-223 MB for a
scheme's first run in a fresh checkout: numba compiling into an empty cache).
Hence ``"dual-mdr"`` and ``"ddfv, tangential"`` are kinds of their own (memory and
time fitted on levels 4-5, the largest of their schemes), and the memory of
``"vertex"`` is refitted on the largest of its schemes (``deturck``; its time kept,
the batching's factor was measured against it): at level 8 (655 362 vertices) it
estimates 2.15 GB against ``deturck``'s 1.55 GB and ``mdr``'s 1.30 GB peak, and
``dual-mdr`` 4.82 GB against 3.57 GB (7.53 against 5.50 GB at 1 024 000 vertices).
Every other kind's estimate was above its schemes' peaks at level 5 and at level 8
and is kept.

* the peak resident memory that grows with the mesh (mesh, flow, solver), above
  a process that made a level-1 run first, ``a n^p`` (slopes 1.06-1.12), plus
  the fixed part the first run of a process takes on (:data:`FIXED_MB`);
* the CPU seconds of one time step, ``b n^q`` (slopes 0.66-1.11);

both on levels 4-5 (below, a run does not rise above the level-1 run's peak
memory, and fixed costs dominate its steps).

``n`` is the number of unknowns (points of the state, ``RunResult.nV``): the
mesh vertices, plus one T-vertex per triangle for DDFV (about 3 times as
many). The fits are machine- and load-dependent; they give the order of
magnitude, which is what the guard needs.

The guard
---------
:func:`check_size` estimates a run's unknowns without building its mesh (the
problem's first level, 4 times the points per level: each level halves the
mesh size), and refuses (:class:`RunTooLarge`, a ``ValueError``: the command
line prints it in one line) a run whose estimated memory is above the memory
the machine has available (``MemAvailable`` of ``/proc/meminfo``), naming both
and the estimated time, unless told to go on (``force``; ``--force`` on the
command line). Where ``/proc/meminfo`` does not exist the available memory is
unknown and every run goes on.
"""

from dataclasses import dataclass

from mcfbench.running.schemes import find_scheme, get_scheme, parse_name
from mcfbench.storage.memory import available_mb

COSTS = {
    "vertex": ((1.179e-3, 1.072), (6.696e-6, 0.660)),
    "dual-mdr": ((5.473e-3, 1.020), (6.485e-6, 0.830)),
    "vertex, redistributing": ((1.402e-3, 1.079), (2.671e-6, 1.113)),
    "ddfv": ((4.547e-4, 1.064), (1.143e-6, 0.825)),
    "ddfv, tangential": ((2.062e-3, 1.009), (2.096e-7, 1.089)),
    "ddfv, redistributing": ((7.923e-4, 1.122), (2.134e-6, 0.947)),
    "bgn": ((9.613e-4, 1.055), (9.14e-6, 0.661)),
    "kll": ((5.815e-4, 1.113), (3.848e-6, 0.763)),
}
"""Kind of scheme (:func:`cost_class`) -> ``((a, p), (b, q))``: memory ``a n^p`` MB above
a warmed-up process and ``b n^q`` CPU seconds per step (module docstring;
``benchmarks/bench_cost.py``: ``cotan``, ``cotan-redistribute``, ``ddfv``,
``ddfv-chord-redistribute-carried``, ``bgn``, ``kll``; refitted 2026-12-07: the
memory of ``vertex`` on ``deturck``, ``dual-mdr`` on itself, ``ddfv, tangential`` on
``ddfv-chord-bgn-carried`` and ``ddfv-chord-mdr-carried``)."""
FIXED_MB = 135.0
"""The memory a process takes on for its first run, whatever its size: numba, the
compiled kernels, scipy's solvers (the level-1 run after the imports)."""

def cost_class(scheme):
    """The kind of a scheme (a name or a registry entry) in :data:`COSTS`: ``"bgn"``
    (a coupled 3n x 3n system), ``"kll"`` (a 7n x 7n one, solved by blocks),
    ``"dual-mdr"`` (its ``(X, R)`` block system: 3-4 x the memory of the other vertex
    schemes), ``"ddfv"`` or ``"vertex"`` (the other vertex schemes), with ``",
    redistributing"`` for a scheme with a tangential redistribution (a potential solved
    at every step) and, for DDFV, ``", tangential"`` for BGN's or MDR's tangential
    motion (their kept factors: twice the memory)."""
    entry = get_scheme(scheme) if isinstance(scheme, str) else scheme
    entry = find_scheme(entry.name) or entry      # a study's wrapper -> the registry's entry
    if parse_name(entry.name).base in ("bgn", "kll", "dual-mdr"):
        return parse_name(entry.name).base
    options = getattr(entry, "options", {})
    kind = entry.family                           # "ddfv" or "vertex": a key of COSTS
    if options.get("redistribution") is not None or options.get("tangential") == "redistribute":
        return f"{kind}, redistributing"
    if kind == "ddfv" and options.get("tangential") in ("bgn", "mdr"):
        return f"{kind}, tangential"
    return kind


@dataclass(frozen=True)
class Estimate:
    """What a run is estimated to cost.

    Attributes
    ----------
    unknowns, steps : int
    memory_mb : float
        Peak resident memory above the process's after its imports, MB (2**20
        bytes): :data:`FIXED_MB` and the part that grows with ``unknowns``.
    seconds : float
        CPU seconds of its steps.
    """

    unknowns: int
    steps: int
    memory_mb: float
    seconds: float


def estimate(scheme, unknowns, steps):
    """:class:`Estimate` of ``steps`` steps of ``scheme`` with ``unknowns`` unknowns
    (the fits of :data:`COSTS`)."""
    (a, p), (b, q) = COSTS[cost_class(scheme)]
    return Estimate(int(unknowns), int(steps), FIXED_MB + a * unknowns ** p,
                    steps * b * unknowns ** q)


class RunTooLarge(ValueError):
    """A run estimated to need more memory than the machine has available."""


def check_size(scheme, problem, level, *, mesh=None, tau=None, t_final=None, force=False):
    """Refuse a run whose estimated peak memory is above the available memory.

    Parameters
    ----------
    scheme, problem : registry entries
    level : int
    mesh : (vertices, faces), optional
        The run's own mesh, when given (its size is then known).
    tau, t_final : float, optional
        As in :func:`mcfbench.running.run.run`.
    force : bool
        Run anyway.

    Returns
    -------
    Estimate

    Raises
    ------
    RunTooLarge
        Naming the estimate (unknowns, memory, time), the available memory and
        how to insist.
    """
    cost = estimate(scheme, *size(scheme, problem, level, mesh=mesh, tau=tau,
                                  t_final=t_final))
    available = available_mb()
    if not force and available is not None and cost.memory_mb > available:
        raise RunTooLarge(
            f"{scheme.name} on the {problem.name} at level {level}: about "
            f"{cost.unknowns:,} unknowns and {cost.steps:,} steps, estimated to need "
            f"{_mb(cost.memory_mb)} of memory (and {_seconds(cost.seconds)} of CPU), but "
            f"{_mb(available)} is available; not run (the estimate is a fit of measured "
            f"runs, mcfbench/running/cost.py: to run it anyway, give --force on the "
            f"command line, force=True to run())")
    return cost


def size(scheme, problem, level, *, mesh=None, tau=None, t_final=None):
    """``(unknowns, steps)`` of a run, without building its mesh when it is the
    problem's: from the problem's first level (built once per process), 4 times
    the points per level (each level halves the mesh size).

    Returns
    -------
    unknowns, steps : int
    """
    if mesh is not None:
        n_vertices, n_faces, scale = len(mesh[0]), len(mesh[1]), 1.0
        tau = problem.tau(level, mesh) if tau is None else tau
    else:
        first = min(problem.levels)
        n_vertices, n_faces, first_tau = _first_level(problem)
        scale = 4.0 ** max(int(level) - first, 0)
        if tau is None:
            tau = problem.tau(level) if problem.tau_rule == "level" else first_tau / scale
    points = n_vertices + (n_faces if scheme.extra_points else 0)   # DDFV: + T-vertices
    if problem.tau_rule == "mesh" and t_final is None:
        steps = problem.steps
    else:
        steps = (problem.t_final if t_final is None else t_final) / tau
    return round(points * scale), max(1, round(steps))


_first_levels = {}
"""(surface, its parameters) -> what :func:`_first_level` measured."""


def _first_level(problem):
    """``(vertices, triangles, tau)`` of the problem's first level, built once per
    process; for a committed real mesh whose time step follows the level, the counts
    of its manifest (:func:`mcfbench.geometry.committed_meshes.mesh_manifest`, level
    0 is the mesh itself) and ``tau`` None, unneeded: no file is read (the matrix's
    batches estimate every series while Snakemake reads the workflow)."""
    from mcfbench.geometry.committed_meshes import mesh_manifest

    first = min(problem.levels)
    params = problem.params(first)
    key = (problem.surface, tuple(sorted((k, repr(v)) for k, v in params.items())))
    if key in _first_levels:
        return _first_levels[key]
    if problem.surface == "real_mesh" and problem.tau_rule == "level" and first == 0:
        entry = mesh_manifest()[params["mesh"]]
        _first_levels[key] = (entry["vertices"], entry["faces"], None)
    else:
        mesh = problem.mesh(first)
        _first_levels[key] = (len(mesh[0]), len(mesh[1]), problem.tau(first, mesh))
    return _first_levels[key]


def _mb(value):
    return f"{value / 2**10:.3g} GB" if value >= 2**10 else f"{value:.3g} MB"


def _seconds(value):
    for unit, seconds in (("days", 86400), ("h", 3600), ("min", 60)):
        if value >= seconds:
            return f"{value / seconds:.3g} {unit}"
    return f"{value:.3g} s"
