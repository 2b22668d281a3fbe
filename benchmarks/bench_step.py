"""The parts of one DDFV step on the sphere of Table 3.1, each the minimum of N calls.

The flow of ``_harness.harness_run("ddfv", level, steps=...)`` (the command
line's run, stopped after ``--steps`` steps) is stepped once more by hand
(the paper's Euler step from ``X^n``) so that the next solve starts from the
integrator's guess ``2 X^n - X^{n-1}``; then, in this one process, each part
is called ``--calls`` times and the fastest call is printed (ms):

* ``geometry``: the diamonds and covolumes of a state (``Flow._geometry_at``),
* ``assembly``: ``Assembler.system`` at that geometry,
* ``barycentric``: the T monitor (``t_barycentric`` with its minimum),
* ``residual``: the solver's first pass (``krylov.residual``: ``b - A x0`` and
  its sums), ``product``: one block product ``A X`` (``krylov.spmv``),
* ``solve``: the whole BiCGStab solve (``solver.solve``) from the guess, with
  its iterations.

One core pinned, one BLAS thread, glibc's malloc tuned. The machine is shared:
compare parts measured in one run (or paired runs, ``bench_ab.py``), not
absolute times across runs.

    python benchmarks/bench_step.py [--level 5] [--steps 250] [--calls 200]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402
from _harness import harness_run, machine_line, one_core  # noqa: E402


def fastest(call, calls):
    """Milliseconds of the fastest of ``calls`` calls of ``call()``."""
    best = np.inf
    for _ in range(calls):
        start = time.perf_counter()
        call()
        best = min(best, time.perf_counter() - start)
    return 1e3 * best


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=5)
    parser.add_argument("--steps", type=int, default=250,
                        help="steps of the run before the parts are timed")
    parser.add_argument("--calls", type=int, default=200)
    args = parser.parse_args(argv)
    one_core()
    from mcfbench.storage.memory import tune_malloc

    tune_malloc()
    from ddfv.geometry import t_barycentric
    from mcfbench.running import krylov
    from mcfbench.running import solver as S

    print(f"bench_step: {machine_line()}")
    _, flow = harness_run("ddfv", args.level, steps=args.steps)
    previous = flow._X.copy()
    A, b = flow.system()
    x, _ = S.solve(A, b, previous)
    flow.advance(x)
    X = flow._X                     # the compiled passes take writable arrays
    A, b = flow.system()
    guess = 2.0 * X - previous
    geometry, chi = flow._geometry_at(X)
    n_f = flow._mesh.n_f
    csr = S._csr(A)
    rhs, x0, cmean, cfull, _ = S._blocks(A, b, guess)
    out = np.empty_like(rhs)
    iterations = S.solve(A, b, guess)[1].iterations
    parts = {
        "geometry": lambda: flow._geometry_at(X),
        "assembly": lambda: flow._assembler.system(geometry, chi, flow.tau),
        "barycentric": lambda: t_barycentric(X[:, :n_f].T, X[:, n_f:].T, flow._mesh.faces,
                                             return_min=True),
        "residual": lambda: krylov.residual(*csr, rhs, x0, cmean, cfull, out),
        "product": lambda: krylov.spmv(*csr, x0, out, rhs),
        "solve": lambda: S.solve(A, b, guess),
    }
    print(f"sphere level {args.level} after {flow.n} steps, {flow._mesh.n_unknowns} unknowns, "
          f"{A.nnz} nonzeros; the solve from 2 X^n - X^(n-1): {iterations} iteration(s)")
    for name, call in parts.items():
        print(f"{name:12s} {fastest(call, args.calls):7.3f} ms (min of {args.calls})")
    print(f"load average at the end: {machine_line()}")


if __name__ == "__main__":
    main()
