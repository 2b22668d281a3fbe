"""A step's bound against its measured time (issue #46, item 2): how far each scheme's
step is from what this machine's memory and arithmetic allow.

In this one process (pinned to one core, one BLAS and numba thread, malloc tuned):

* ``B``: the STREAM triad ``a = b + s c`` (a compiled loop, float64 arrays of
  ``--triad-mb`` MB each, preallocated, far larger than the last-level cache),
  the best of ``--triad-repeats``, counted as STREAM counts it: 3 x 8 bytes per
  element (two reads, one write; no write-allocate traffic counted).
* ``F``: numpy's ``matmul`` of two (2000, 2000) float64 matrices on one thread,
  ``2 n^3`` flops, the best of three.

Then for each scheme and sphere level (Table 3.1's problem, ``tau = 0.04 /
4^(k-1)``, i.e. about ``0.1 h^2``): the registry's flow stepped by
:func:`mcfbench.running.driver.simulate` (the run's checks on, BiCGStab at rtol
1e-9 from the integrator's extrapolation ``2 X^n - X^{n-1}``) for one warm-up
step and ``--steps`` timed steps; an observer reads the CPU clock at every time
level, so a step's time is that of everything between two levels (assembly,
solve, the driver's checks, the integrator). Printed per scheme and level: the
median CPU ms per timed step, the iterations per step (the solver's, counted by a
wrapper around :class:`mcfbench.running.solver.Solver`), the bytes and flops of
the counting model below, ``bound = max(bytes / B, flops / F)`` and ``measured /
bound``.

The counting model: the least a step of this algorithm must move, every array
read or written once per pass from memory (no cache reuse between passes, none
within the matrix's rows' gathers: the vector entries a row reads are counted
once per pass, as if every gather hit the cache), bytes as STREAM counts them.
For each linear solve of the step, ``A`` with ``Z`` stored entries, ``m`` rows,
index bytes ``i`` (4 for int32), a block of ``k`` right-hand sides of ``m``
entries (``k = 3`` for a matrix shared by the coordinates, ``k = 1`` for a
coupled ``(3n, 3n)`` one), ``V = 8 k m`` the bytes of one vector block:

* a product ``A X``: ``Z (8 + i) + (m + 1) i`` bytes of the matrix and ``2 V``
  (read ``X``, write ``A X``); ``2 k Z`` flops;
* the residual pass (one product, then reads of ``b`` and ``x``, the write of
  ``r``): one product + ``2 V``; the start of the iteration (``r_hat = p = r``):
  ``3 V``;
* each BiCGStab iteration (the kernel's fused passes, ``krylov.bicgstab_kernel``):
  two products and the vector passes ``(r_hat, v)`` 1, ``s = r - alpha v`` 3, ``(t,
  s), (t, t)`` 1, ``x, r`` and their sums 7, ``p`` 4: ``16 V`` besides the
  products, ``26 k m`` flops besides them;
* with a kept incomplete LU (``ilu-bicgstab``: KLL's ``S`` where its diagonal spreads,
  ``baselines.kll.SPREAD``), its two applications an iteration: the factors' ``F``
  stored entries, ``F (8 + i) + 2 (m + 1) i`` bytes, and the passes of
  ``krylov.precondition`` (scaled copy, forward, backward, permuted copy): ``8 V +
  8 m``; ``2 k F + k m`` flops. The factor's making (amortised over the steps it
  is kept, not in the timed steps unless made anew there) is not counted;
* the assembly: the state read (``V``), the mesh's faces read once (``3 i`` per
  face) and the matrix values (``8 Z``) and the right-hand side (``V``) written;
  ``100`` flops per face (a triangle's cotangents, areas, normals: counted
  generously, the flops never bind);
* the rest of the step: the integrator's guess (read ``X^n``, ``X^{n-1}``, write
  ``x0``: ``3 V``) and the driver's checks of the new state (its positions and
  faces read once).

A solve of zero iterations is the residual pass alone. Systems a scheme solves
outside the run's solver (the redistribution's potential: ``cholespy``) are not
counted: their bound is left out, their time is in the measured step. The ratio
is therefore a lower estimate of how far the step is from the hardware only when
all of its solves go through the run's solver (every scheme of the default list).

The mesh is stepped as a run steps it (``--orders harness``: renumbered for locality
from :data:`mcfbench.running.locality.MIN_VERTICES` vertices on,
:func:`mcfbench.running.locality.locality_order`), in the icosphere's own order
(``input``) or renumbered at every size (``locality``); several orders are
interleaved in this one process.

Usage::

    python benchmarks/bench_bound.py [--levels 5 6 7] [--schemes cotan bgn ...]
        [--steps N] [--repeats 2] [--triad-mb 1024] [--orders harness input locality]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from _harness import footing, machine_line, one_core  # noqa: E402

SCHEMES = ["cotan", "bgn", "ddfv-chord-carried", "cmcf"]
#: timed steps per level (after one warm-up step) unless ``--steps``
ORDERS = ("harness", "input", "locality")
"""The vertex orders a step is measured in (:func:`measure`)."""
STEPS = {4: 60, 5: 40, 6: 16, 7: 6, 8: 3}
FACE_FLOPS = 100
ITERATION_VECTORS = 16
ITERATION_FLOPS = 26


def triad_kernel():
    """The compiled STREAM triad ``a[i] = b[i] + s c[i]`` (no parallel loop)."""
    import numba

    @numba.njit(cache=False, nogil=True)
    def triad(a, b, c, s):
        for i in range(a.size):
            a[i] = b[i] + s * c[i]

    return triad


def stream_bandwidth(megabytes, repeats):
    """``B`` in bytes per second: the best of ``repeats`` triads of ``megabytes`` MB
    arrays, 24 bytes per element."""
    n = int(megabytes * 2**20) // 8
    a, b, c = np.zeros(n), np.full(n, 1.0), np.full(n, 2.0)
    triad = triad_kernel()
    triad(a, b, c, 3.0)                     # compile, and touch every page
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        triad(a, b, c, 3.0)
        best = min(best, time.perf_counter() - start)
    if not np.all(a[:: max(1, n // 1000)] == 7.0):
        raise RuntimeError("the triad computed a wrong value")
    return 24.0 * n / best


def flop_rate(size=2000, repeats=3):
    """``F`` in flops per second: numpy's matmul of two (size, size) matrices."""
    x = np.random.default_rng(0).random((size, size))
    y = np.random.default_rng(1).random((size, size))
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        x @ y
        best = min(best, time.perf_counter() - start)
    return 2.0 * size**3 / best


class CountingSolver:
    """The run's solver (:class:`mcfbench.running.solver.Solver`, defaults but its
    ``threads``) recording,
    per call, ``(step, iterations, Z, m, k, index bytes, F)`` (``F`` the stored entries
    of the incomplete LU the solve applied, 0 for none); ``step`` is read from
    :attr:`step` (set by the observer)."""

    can_overwrite_x0 = True

    def __init__(self, threads=1):
        from mcfbench.running.solver import Solver

        self._solver = Solver(threads=threads)
        self.calls = []
        self.step = 0

    def __call__(self, A, b, x0, *, overwrite_x0=False):
        x, info = self._solver(A, b, x0, overwrite_x0=overwrite_x0)
        shared = A.shared if hasattr(A, "substitute") else A
        k = np.shape(b)[0] if shared.shape[0] == np.shape(b)[-1] else 1
        factor = getattr(A, "preconditioner", None) if info.method == "ilu-bicgstab" else None
        self.calls.append((self.step, info.iterations, shared.nnz, shared.shape[0], k,
                           shared.indices.dtype.itemsize,
                           0 if factor is None else factor.L.nnz + factor.U.nnz))
        return x, info


def solve_cost(iterations, Z, m, k, i, F=0):
    """``(bytes, flops)`` of one solve (module docstring); ``F`` the incomplete LU's
    stored entries (0: none)."""
    V = 8 * k * m
    product = Z * (8 + i) + (m + 1) * i + 2 * V
    nbytes = product + 2 * V
    flops = 2 * k * Z
    if iterations:
        applied = (F * (8 + i) + 2 * (m + 1) * i + 8 * V + 8 * m) if F else 0
        nbytes += 3 * V + iterations * (2 * product + ITERATION_VECTORS * V + 2 * applied)
        flops += iterations * (4 * k * Z + ITERATION_FLOPS * k * m
                               + (2 * (2 * k * F + k * m) if F else 0))
    return nbytes, flops


def step_cost(calls, positions, faces):
    """``(bytes, flops)`` of one step's solves (``calls``: its recorded solves), its
    assemblies and the rest (module docstring); ``positions`` and ``faces`` the mesh's
    shapes ``(n_v, n_f)``, the faces' index bytes."""
    n_v, n_f, fi = positions[0], faces[0], faces[1]
    nbytes = flops = 0
    for _, iterations, Z, m, k, i, F in calls:
        sb, sf = solve_cost(iterations, Z, m, k, i, F)
        V = 8 * k * m
        nbytes += sb + V + 3 * fi * n_f + 8 * Z + V + 3 * V
        flops += sf + FACE_FLOPS * n_f
    nbytes += 24 * n_v + 3 * fi * n_f
    return nbytes, flops


def measure(name, level, steps, mesh=None, order="input", tau=None, threads=1,
            clock=time.process_time):
    """One run of ``name`` on the sphere at ``level`` (or on ``mesh``, ``(V, F)``, with
    the sphere's time step of ``level`` unless ``tau``) in ``order`` (:data:`ORDERS`),
    the flow made and its solves run with ``threads`` threads, each step timed by
    ``clock`` (CPU seconds; the wall's for several threads): ``(ms per step: the
    median of the timed steps, iterations per timed step, bytes per step, flops per
    step, vertices)``."""
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.running.driver import simulate
    from mcfbench.running.locality import locality_order
    from mcfbench.running.problems import get_problem
    from mcfbench.running.schemes import get_scheme

    V, F = icosphere(level) if mesh is None else mesh
    renumbered = None if order == "input" else \
        locality_order(V, F, min_vertices=0 if order == "locality" else None)
    V, F = (V, F) if renumbered is None else renumbered.mesh(V, F)
    tau = get_problem("sphere").tau(level) if tau is None else tau
    flow = get_scheme(name).make(V, F, tau, threads=threads)
    solver = CountingSolver(threads)
    times = []

    def observer(_flow):
        times.append(clock())
        solver.step = len(times)           # the solves that follow are of this step

    traj = simulate(flow, steps + 1, solver=solver, save_every=0, observers=[observer])
    if not traj.ok:
        raise RuntimeError(f"{name} level {level}: {traj.message}")
    per_step = np.diff(times)[1:]          # the first step is the warm-up
    timed = [c for c in solver.calls if c[0] >= 2]
    costs = [step_cost([c for c in timed if c[0] == s], flow.vertices.shape,
                       (flow.faces.shape[0], flow.faces.dtype.itemsize))
             for s in range(2, steps + 2)]
    return (1e3 * statistics.median(per_step), sum(c[1] for c in timed) / steps,
            statistics.median(c[0] for c in costs), statistics.median(c[1] for c in costs),
            len(V))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[5, 6, 7])
    parser.add_argument("--schemes", nargs="+", default=SCHEMES)
    parser.add_argument("--steps", type=int, default=None,
                        help=f"timed steps per run (default per level: {STEPS})")
    parser.add_argument("--repeats", type=int, default=2,
                        help="runs per scheme and level, interleaved; the best is kept")
    parser.add_argument("--triad-mb", type=float, default=1024.0,
                        help="MB of each of the triad's three arrays")
    parser.add_argument("--triad-repeats", type=int, default=10)
    parser.add_argument("--orders", nargs="+", choices=ORDERS, default=["harness"],
                        help="vertex orders, interleaved (harness: as a run steps it)")
    args = parser.parse_args(argv)
    one_core()
    from mcfbench.storage.memory import tune_malloc

    tune_malloc()
    print(machine_line())
    B = stream_bandwidth(args.triad_mb, args.triad_repeats)
    F = flop_rate()
    print(f"B = {B / 1e9:.2f} GB/s (STREAM triad, 3 x {args.triad_mb:g} MB, best of "
          f"{args.triad_repeats}, 24 bytes per element); F = {F / 1e9:.1f} GFlop/s (matmul "
          f"2000^2, one thread, best of 3)")
    for name in args.schemes:                 # compile and load every kernel first
        measure(name, 1, 2)
    best = {}
    for repeat in range(args.repeats):
        for level in args.levels:
            runs = [(name, order) for name in args.schemes for order in args.orders]
            for name, order in runs if repeat % 2 == 0 else runs[::-1]:
                steps = args.steps or STEPS.get(level, 3)
                row = measure(name, level, steps, order=order)
                old = best.get((name, level, order))
                best[(name, level, order)] = row if old is None or row[0] < old[0] else old
                print(f"  [{time.strftime('%H:%M:%S')} load {os.getloadavg()[0]:.2f}] "
                      f"{name} level {level} {order}: {row[0]:.2f} ms/step, "
                      f"{row[1]:.2f} it/step", flush=True)
    print(f"\n{machine_line()}")
    print(f"{'scheme':>28} {'level':>5} {'order':>8} {'vertices':>9} {'ms/step':>9} "
          f"{'it/step':>7} {'MB/step':>8} {'MFlop/step':>10} {'bound ms':>9} {'ratio':>6}")
    for name in args.schemes:
        for level in args.levels:
            for order in args.orders:
                ms, it, nbytes, flops, nv = best[(name, level, order)]
                bound = 1e3 * max(nbytes / B, flops / F)
                print(f"{name:>28} {level:>5} {order:>8} {nv:>9} {ms:>9.2f} {it:>7.2f} "
                      f"{nbytes / 1e6:>8.1f} {flops / 1e6:>10.1f} {bound:>9.3f} "
                      f"{ms / bound:>6.1f}")
    print("bound = max(bytes / B, flops / F), the counting model of the module docstring; "
          "ms/step: the median CPU ms of the timed steps, the best of the repeats")
    print(footing())


if __name__ == "__main__":
    main()
