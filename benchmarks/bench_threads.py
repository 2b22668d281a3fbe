"""Both cores on one large run (issue #46, item 3): a step with ``threads=2`` against the
same step with one thread, beside the STREAM triad's own two-thread over one-thread
ratio, in one process.

* The triad ``a = b + s c`` compiled with a parallel loop (numba ``prange``), float64
  arrays of ``--triad-mb`` MB each, preallocated; run with numba set to one thread and
  to two, interleaved, the best of ``--triad-repeats`` each: ``R = B_2 / B_1``, what
  the memory gives a second core on this machine.
* Each scheme on the sphere at ``--levels`` (renumbered for locality as a run is,
  ``bench_bound.measure``), the flow made and its solves run with ``threads=1`` and
  ``threads=2`` (:meth:`mcfbench.running.scheme.Scheme.make`,
  :class:`mcfbench.running.solver.Solver`), interleaved, ``--repeats`` times each: one
  warm-up step and ``--steps`` timed ones, the median **wall** ms per step (CPU seconds
  add the threads' up), the best of the repeats. Printed: both, the speedup ``S =
  ms_1 / ms_2`` and ``S / R`` (the issue's target: at least 0.8).

* ``--passes``: instead, each threaded part of a vertex scheme's step on its own
  (``--schemes`` cotan, bgn), one thread against two on the same state, interleaved,
  the best of ``--repeats`` each: the assembly (``flow.system(at=X)``: the geometry and
  the system's rows), the flow's triangle checks, the driver's measuring pass
  (:class:`mcfbench.geometry.measures.StateMeasures`) and the solve from the state.

Not pinned (two threads need both cores); every other thread pool at one thread. A
second core only helps when nobody else uses it: the load average is printed with
every measurement, and the numbers mean something only near an idle machine (load
below 1).

Usage::

    python benchmarks/bench_threads.py [--levels 8] [--schemes cotan bgn ddfv-chord-carried]
        [--steps 3] [--repeats 3] [--triad-mb 512] [--passes]
"""

import argparse
import os
import time

from bench_bound import measure  # sets every thread pool to one thread, numpy imported

os.environ["NUMBA_NUM_THREADS"] = "2"  # but numba's: read once, when it is first imported

import numba  # noqa: E402
import numpy as np  # noqa: E402
from _harness import footing, machine_line  # noqa: E402

SCHEMES = ["cotan", "bgn", "ddfv-chord-carried"]


def parallel_triad():
    """The STREAM triad ``a[i] = b[i] + s c[i]`` with a parallel loop."""
    @numba.njit(parallel=True, cache=False, nogil=True)
    def triad(a, b, c, s):
        for i in numba.prange(a.size):
            a[i] = b[i] + s * c[i]

    return triad


def triad_ratio(megabytes, repeats):
    """``(B_1, B_2)`` in bytes per second: the parallel triad with numba at one thread
    and at two, interleaved, the best of ``repeats`` each (24 bytes per element)."""
    n = int(megabytes * 2**20) // 8
    a, b, c = np.zeros(n), np.full(n, 1.0), np.full(n, 2.0)
    triad = parallel_triad()
    best = {1: np.inf, 2: np.inf}
    for threads in (1, 2):                  # compile, and touch every page
        numba.set_num_threads(threads)
        triad(a, b, c, 3.0)
    for _ in range(repeats):
        for threads in (1, 2):
            numba.set_num_threads(threads)
            start = time.perf_counter()
            triad(a, b, c, 3.0)
            best[threads] = min(best[threads], time.perf_counter() - start)
    numba.set_num_threads(1)
    if not np.all(a[:: max(1, n // 1000)] == 7.0):
        raise RuntimeError("the triad computed a wrong value")
    return 24.0 * n / best[1], 24.0 * n / best[2]


def passes(name, level, repeats):
    """``{part: (ms on one thread, ms on two)}`` for the threaded parts of a vertex
    scheme's step (module docstring), the best of ``repeats`` interleaved calls."""
    from mcfbench.geometry.measures import StateMeasures
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.running.locality import locality_order
    from mcfbench.running.problems import get_problem
    from mcfbench.running.schemes import get_scheme
    from mcfbench.running.solver import Solver

    V, F = icosphere(level)
    renumbered = locality_order(V, F)
    V, F = (V, F) if renumbered is None else renumbered.mesh(V, F)
    tau = get_problem("sphere").tau(level)
    flows = {t: get_scheme(name).make(V, F, tau, threads=t) for t in (1, 2)}
    measures = {t: StateMeasures(V, F, threads=t) for t in (1, 2)}
    X = np.array(flows[1].state)
    A, b = flows[1].system()
    parts = {
        "assembly": lambda t: flows[t].system(at=X),
        "triangle checks": lambda t: (flows[t].__dict__.pop("_triangle_checks", None),
                                      flows[t]._triangle_checks),
        "measuring pass": lambda t: measures[t](V),
        "solve": lambda t: Solver(threads=t)(A, b, X),
    }
    best = {}
    for part, call in parts.items():
        for t in (1, 2):
            call(t)                       # compile or load, first touch
        for r in range(repeats):
            for t in (1, 2) if r % 2 == 0 else (2, 1):
                start = time.perf_counter()
                call(t)
                ms = 1e3 * (time.perf_counter() - start)
                best[part, t] = min(best.get((part, t), np.inf), ms)
    return {part: (best[part, 1], best[part, 2]) for part in parts}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[8])
    parser.add_argument("--schemes", nargs="+", default=SCHEMES)
    parser.add_argument("--steps", type=int, default=3)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--triad-mb", type=float, default=512.0)
    parser.add_argument("--triad-repeats", type=int, default=10)
    parser.add_argument("--passes", action="store_true",
                        help="each threaded part of cotan's or BGN's step on its own")
    args = parser.parse_args(argv)
    from mcfbench.storage.memory import tune_malloc

    tune_malloc()
    print(machine_line())
    load = os.getloadavg()[0]
    B1, B2 = triad_ratio(args.triad_mb, args.triad_repeats)
    R = B2 / B1
    print(f"triad: B_1 = {B1 / 1e9:.2f} GB/s, B_2 = {B2 / 1e9:.2f} GB/s, R = B_2 / B_1 = "
          f"{R:.2f} (3 x {args.triad_mb:g} MB, best of {args.triad_repeats}; load "
          f"{load:.2f})", flush=True)
    if args.passes:
        print(f"{'scheme':>8} {'level':>5} {'part':>16} {'1 thread ms':>11} "
              f"{'2 threads ms':>12} {'S':>5} {'S / R':>6} {'load':>5}")
        for level in args.levels:
            for name in args.schemes:
                load = os.getloadavg()[0]
                for part, (one, two) in passes(name, level, args.repeats).items():
                    print(f"{name:>8} {level:>5} {part:>16} {one:>11.2f} {two:>12.2f} "
                          f"{one / two:>5.2f} {one / two / R:>6.2f} {load:>5.2f}", flush=True)
        print(f"the best of {args.repeats} interleaved calls each; S = ms_1 / ms_2")
        return
    for name in args.schemes:                 # compile and load every kernel first
        for threads in (1, 2):
            measure(name, 1, 2, threads=threads)
    best = {}
    for repeat in range(args.repeats):
        for level in args.levels:
            for name in args.schemes:
                for threads in (1, 2) if repeat % 2 == 0 else (2, 1):
                    load = os.getloadavg()[0]
                    ms = measure(name, level, args.steps, order="harness", threads=threads,
                                 clock=time.perf_counter)[0]
                    key = (name, level, threads)
                    best[key] = min(best.get(key, (np.inf, 0)), (ms, load))
                    print(f"  [{time.strftime('%H:%M:%S')} load {load:.2f}] {name} level "
                          f"{level} threads {threads}: {ms:.1f} wall ms/step", flush=True)
    print(f"\n{machine_line()}")
    print(f"R = {R:.2f} (the parallel triad's B_2 / B_1)")
    print(f"{'scheme':>28} {'level':>5} {'1 thread ms':>11} {'2 threads ms':>12} "
          f"{'S':>5} {'S / R':>6} {'loads':>11}")
    for name in args.schemes:
        for level in args.levels:
            (one, l1), (two, l2) = best[(name, level, 1)], best[(name, level, 2)]
            print(f"{name:>28} {level:>5} {one:>11.1f} {two:>12.1f} {one / two:>5.2f} "
                  f"{one / two / R:>6.2f} {l1:>5.2f}/{l2:<5.2f}")
    print("wall ms per step: the median of the timed steps after one warm-up step, the "
          "best of the repeats (the load average when that run began); S = ms_1 / ms_2")
    print(footing().replace("one core, ", "one core or two as said, "))


if __name__ == "__main__":
    main()
