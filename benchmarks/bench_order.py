"""Vertex order for locality (issue #46, item 3): a scheme's step on the icosphere in
its own order (the refinement's: each level's new vertices after the old ones, so
that neighbours lie far apart in memory) against the same mesh renumbered once by
reverse Cuthill-McKee (the harness's :func:`mcfbench.running.locality.locality_order`:
``scipy.sparse.csgraph.reverse_cuthill_mckee`` on the vertex adjacency, the faces
then sorted by their smallest vertex) and by a space-filling curve (Morton's
Z-order of the vertices' positions quantised to 2^21 cells a side, the faces sorted
the same way).

``--runs``: the whole run's CPU (:func:`mcfbench.running.run.run`, its ``cpu_seconds``:
the flow's construction and every step with the checks and observers) of the
sphere problem at the given levels, renumbered by the harness's order and kept in
its own order (:data:`mcfbench.running.locality.MIN_VERTICES` set to 0 and above the
mesh's size), alternately, ``--repeats`` times, the best kept; and the renumbering's
own cost (ordering, renumbering the mesh, undoing two frames), outside the run's
timed part.

Both orders of each level are stepped alternately in this one process (pinned to one
core, one thread, malloc tuned), ``--repeats`` times, by
:func:`bench_bound.measure` (one warm-up step, then the median CPU ms of the timed
steps; the best of the repeats); printed: ms per step of each order, their ratio,
the iterations per step (the same problem: they should agree), and the bandwidth of
the vertex adjacency in each order.

Usage::

    python benchmarks/bench_order.py [--levels 6 7 8] [--schemes cotan] [--repeats 3]
    python benchmarks/bench_order.py --runs --levels 5 6 [--schemes cotan] [--repeats 2]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse as sp  # noqa: E402
from _harness import machine_line, one_core  # noqa: E402
from bench_bound import STEPS, measure  # noqa: E402


def adjacency(faces, n):
    """(n, n) CSR vertex adjacency of the triangles ``faces`` (m, 3)."""
    rows = faces[:, [0, 1, 2, 1, 2, 0]].ravel()
    cols = faces[:, [1, 2, 0, 0, 1, 2]].ravel()
    return sp.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))


def rcm_order(V, F):
    """``(V', F')``: the harness's renumbering (reverse Cuthill-McKee)."""
    from mcfbench.running.locality import locality_order

    return locality_order(V, F, min_vertices=0).mesh(V, F)


def _spread(q):
    """The bits of the 21-bit integers ``q`` spread to every third bit (Morton)."""
    q = q.astype(np.uint64) & np.uint64(0x1FFFFF)
    for shift, mask in ((32, 0x1F00000000FFFF), (16, 0x1F0000FF0000FF),
                        (8, 0x100F00F00F00F00F), (4, 0x10C30C30C30C30C3),
                        (2, 0x1249249249249249)):
        q = (q | (q << np.uint64(shift))) & np.uint64(mask)
    return q


def morton_order(V, F):
    """``(V', F')``: ``V`` renumbered along Morton's Z-order curve of its positions,
    the faces renamed and sorted by their smallest vertex (stable)."""
    lo, hi = V.min(axis=0), V.max(axis=0)
    q = ((V - lo) / np.where(hi > lo, hi - lo, 1.0) * (2 ** 21 - 1)).astype(np.uint64)
    code = _spread(q[:, 0]) | (_spread(q[:, 1]) << np.uint64(1)) | \
        (_spread(q[:, 2]) << np.uint64(2))
    perm = np.argsort(code, kind="stable")
    rank = np.empty_like(perm)
    rank[perm] = np.arange(len(perm))
    faces = rank[F]
    return V[perm], faces[np.argsort(faces.min(axis=1), kind="stable")]


ORDERS = {"rcm": rcm_order, "morton": morton_order}
"""The renumberings measured against the icosphere's own order."""


def whole_runs(levels, schemes, repeats):
    """Print the whole run's CPU seconds of each scheme on the sphere at each level,
    renumbered and not (whatever the harness's threshold), and the renumbering's own
    cost."""
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.running import locality
    from mcfbench.running.run import run

    default, best = locality.MIN_VERTICES, {}
    for repeat in range(repeats):
        for level in levels:
            for name in schemes:
                for ordered in (True, False)[:: 1 if repeat % 2 == 0 else -1]:
                    locality.MIN_VERTICES = 0 if ordered else 2 ** 62
                    result = run(name, "sphere", level)[0]
                    key = (name, level, ordered)
                    best[key] = min(best.get(key, np.inf), result.cpu_seconds)
                    print(f"  [{time.strftime('%H:%M:%S')} load {os.getloadavg()[0]:.2f}] "
                          f"{name} level {level} {'ordered' if ordered else 'input'}: "
                          f"{result.cpu_seconds:.2f} s, {result.steps_done} steps, "
                          f"{result.iterations} iterations, l2_error "
                          f"{result.metrics['l2_error']:.10g}", flush=True)
    locality.MIN_VERTICES = default
    print(f"\n{machine_line()}")
    print(f"{'scheme':>20} {'level':>5} {'input s':>9} {'ordered s':>9} {'ratio':>6} "
          f"{'order s':>8}")
    for level in levels:
        V, F = icosphere(level)
        start = time.process_time()
        order = locality.locality_order(V, F, min_vertices=0)
        order.mesh(V, F)
        order.frames({"vertices": np.stack([V, V])})
        cost = time.process_time() - start
        for name in schemes:
            plain, ordered = best[(name, level, False)], best[(name, level, True)]
            print(f"{name:>20} {level:>5} {plain:>9.2f} {ordered:>9.2f} "
                  f"{ordered / plain:>6.3f} {cost:>8.3f}")
    print(f"s: the run's cpu_seconds, the best of {repeats}; order s: the renumbering "
          "and its undoing on two frames (not in the run's time)")


def bandwidth(F, n):
    """The largest ``|i - j|`` over the edges of ``F``."""
    A = adjacency(F, n).tocoo()
    return int(np.abs(A.row - A.col).max())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[6, 7, 8])
    parser.add_argument("--schemes", nargs="+", default=["cotan"])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--runs", action="store_true",
                        help="whole runs of the sphere problem, with and without the order")
    args = parser.parse_args(argv)
    one_core()
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.storage.memory import tune_malloc

    tune_malloc()
    if args.runs:
        return whole_runs(args.levels, args.schemes, args.repeats)
    print(machine_line())
    for name in args.schemes:
        measure(name, 1, 2)
    meshes, names = {}, ["icosphere", *ORDERS]
    for level in args.levels:
        V, F = icosphere(level)
        meshes[level] = {"icosphere": (V, F), **{o: ORDERS[o](V, F) for o in ORDERS}}
    best = {}
    for repeat in range(args.repeats):
        for level in args.levels:
            for name in args.schemes:
                for order in names[:: 1 if repeat % 2 == 0 else -1]:
                    row = measure(name, level, STEPS.get(level, 3), meshes[level][order])
                    key = (name, level, order)
                    best[key] = row if key not in best or row[0] < best[key][0] else best[key]
                    print(f"  [{time.strftime('%H:%M:%S')} load {os.getloadavg()[0]:.2f}] "
                          f"{name} level {level} {order}: {row[0]:.2f} ms/step, "
                          f"{row[1]:.2f} it/step", flush=True)
    print(f"\n{machine_line()}")
    print(f"{'scheme':>10} {'level':>5} {'vertices':>9} {'order':>9} {'ms':>9} "
          f"{'/ ico':>6} {'it':>6} {'bw':>8}")
    for name in args.schemes:
        for level in args.levels:
            ico = best[(name, level, "icosphere")]
            for order in names:
                row, (V, F) = best[(name, level, order)], meshes[level][order]
                print(f"{name:>10} {level:>5} {len(V):>9} {order:>9} {row[0]:>9.2f} "
                      f"{row[0] / ico[0]:>6.3f} {row[1]:>6.2f} {bandwidth(F, len(V)):>8}")
    print("ms: the median CPU ms of the timed steps after a warm-up step, the best of the "
          "repeats; it: iterations per step; bw: the adjacency's bandwidth")


if __name__ == "__main__":
    main()
