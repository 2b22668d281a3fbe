"""Vertex order for locality (issue #46, item 3): a scheme's step on the icosphere in
its own order (the refinement's: each level's new vertices after the old ones, so
that neighbours lie far apart in memory) against the same mesh renumbered once by
reverse Cuthill-McKee (``scipy.sparse.csgraph.reverse_cuthill_mckee`` on the vertex
adjacency, the faces then sorted by their smallest vertex).

Both orders of each level are stepped alternately in this one process (pinned to one
core, one thread, malloc tuned), ``--repeats`` times, by
:func:`bench_bound.measure` (one warm-up step, then the median CPU ms of the timed
steps; the best of the repeats); printed: ms per step of each order, their ratio,
the iterations per step (the same problem: they should agree), and the bandwidth of
the vertex adjacency in each order.

Usage::

    python benchmarks/bench_order.py [--levels 6 7 8] [--schemes cotan] [--repeats 3]
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
    """``(V', F')``: ``V`` renumbered by reverse Cuthill-McKee on its adjacency, the
    faces renamed and sorted by their smallest vertex (stable)."""
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    perm = reverse_cuthill_mckee(adjacency(F, len(V)), symmetric_mode=True)
    rank = np.empty_like(perm)
    rank[perm] = np.arange(len(perm))
    faces = rank[F]
    return V[perm], faces[np.argsort(faces.min(axis=1), kind="stable")]


def bandwidth(F, n):
    """The largest ``|i - j|`` over the edges of ``F``."""
    A = adjacency(F, n).tocoo()
    return int(np.abs(A.row - A.col).max())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[6, 7, 8])
    parser.add_argument("--schemes", nargs="+", default=["cotan"])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    one_core()
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.storage.memory import tune_malloc

    tune_malloc()
    print(machine_line())
    for name in args.schemes:
        measure(name, 1, 2)
    meshes = {}
    for level in args.levels:
        V, F = icosphere(level)
        meshes[level] = {"icosphere": (V, F), "rcm": rcm_order(V, F)}
    best = {}
    for repeat in range(args.repeats):
        for level in args.levels:
            for name in args.schemes:
                orders = ["icosphere", "rcm"][:: 1 if repeat % 2 == 0 else -1]
                for order in orders:
                    row = measure(name, level, STEPS.get(level, 3), meshes[level][order])
                    key = (name, level, order)
                    best[key] = row if key not in best or row[0] < best[key][0] else best[key]
                    print(f"  [{time.strftime('%H:%M:%S')} load {os.getloadavg()[0]:.2f}] "
                          f"{name} level {level} {order}: {row[0]:.2f} ms/step, "
                          f"{row[1]:.2f} it/step", flush=True)
    print(f"\n{machine_line()}")
    print(f"{'scheme':>10} {'level':>5} {'vertices':>9} {'ico ms':>9} {'rcm ms':>9} "
          f"{'rcm/ico':>8} {'ico it':>7} {'rcm it':>7} {'ico bw':>8} {'rcm bw':>8}")
    for name in args.schemes:
        for level in args.levels:
            ico, rcm = best[(name, level, "icosphere")], best[(name, level, "rcm")]
            (V, F), (_, G) = meshes[level]["icosphere"], meshes[level]["rcm"]
            print(f"{name:>10} {level:>5} {len(V):>9} {ico[0]:>9.2f} {rcm[0]:>9.2f} "
                  f"{rcm[0] / ico[0]:>8.3f} {ico[1]:>7.2f} {rcm[1]:>7.2f} "
                  f"{bandwidth(F, len(V)):>8} {bandwidth(G, len(V)):>8}")
    print("ms: the median CPU ms of the timed steps after a warm-up step, the best of the "
          "repeats; bw: the adjacency's bandwidth")


if __name__ == "__main__":
    main()
