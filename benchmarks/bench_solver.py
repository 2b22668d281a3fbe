"""Time the shared linear solver (mcfbench.running.solver) against the former numpy BiCGStab.

The systems are those of the first two time steps of the sphere experiment
(Table 3.1) at one level (default 5: 30722 unknowns, 276482 entries),
captured from ``ddfv.Flow``: step 1 starts from ``X^0``, step 2 from the
extrapolation ``2 X^1 - X^0`` (the default warm start). In this one process,
with old and new interleaved, it prints the median time of

* one block product: three scipy CSR products (the former ``apply_block``)
  against the compiled product of the (3, n) block;
* one solve at ``rtol = 1e-9`` (and 1e-12): the former numpy BiCGStab (a
  literal copy below) against ``solve(method="bicgstab")``; same iteration
  counts are checked;
* one BiCGStab iteration (``maxiter`` = 1 and 6 at an unreachable tolerance);
* the other methods on the same system;
* the numba compilation, cold (empty cache directory) and cached, each in
  a fresh interpreter.

Compare ratios, not absolute seconds (the machine is shared and noisy).

    python benchmarks/bench_solver.py [--level 5] [--repeats 30]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from mcfbench.running.solver import METHODS, Solver, apply_block, solve  # noqa: E402


# --- the former implementation (ddfv/solver.py at 6cc720c), for comparison ---
def old_apply_block(A, X, out=None):
    if out is None:
        out = np.empty_like(X)
    for k, x in enumerate(X):
        out[k] = A @ x
    return out


def old_bicgstab(A, b, x0, rtol=1e-10, maxiter=1000):
    """Returns ``(x, iterations, converged)``."""
    def dot(x, y):
        return float(np.vdot(x, y))

    def norm(x):
        return float(np.sqrt(np.vdot(x, x)))

    bnorm = norm(b)
    if bnorm == 0.0:
        return np.zeros_like(b), 0, True
    tol = rtol * bnorm
    x = np.array(x0, dtype=float, copy=True)
    r = old_apply_block(A, x)
    np.subtract(b, r, out=r)
    rnorm = norm(r)
    if rnorm <= tol:
        return x, 0, True
    r_hat, p, v, s, t, work = (np.empty_like(r) for _ in range(6))
    r_hat[...] = p[...] = r
    rho = dot(r_hat, r)
    for it in range(1, maxiter + 1):
        old_apply_block(A, p, out=v)
        alpha = rho / dot(r_hat, v)
        np.subtract(r, np.multiply(v, alpha, out=work), out=s)
        x += np.multiply(p, alpha, out=work)
        snorm = norm(s)
        if snorm <= tol:
            return x, it, True
        old_apply_block(A, s, out=t)
        tt = dot(t, t)
        omega = dot(t, s) / tt if tt > 0.0 else 0.0
        if omega == 0.0:
            return x, it, False
        x += np.multiply(s, omega, out=work)
        np.subtract(s, np.multiply(t, omega, out=work), out=r)
        rnorm = norm(r)
        if rnorm <= tol:
            return x, it, True
        rho_new = dot(r_hat, r)
        if rho_new == 0.0:
            return x, it, False
        beta = (rho_new / rho) * (alpha / omega)
        rho = rho_new
        p -= np.multiply(v, omega, out=work)
        p *= beta
        p += r
    return x, maxiter, False


# --- the systems --------------------------------------------------------------
def sphere_systems(level):
    """``[(A, b, x0)]`` of the first two steps of the Table 3.1 run at ``level``."""
    from ddfv import Flow
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.running.integrators import Euler

    V, F = icosphere(level)
    flow = Flow(V, F, 0.04 / 4.0 ** (level - 1))
    captured = []

    def record(A, b, x0):
        captured.append((A.tocsr(copy=True), np.array(b), np.array(x0)))
        return Solver()(A, b, x0)

    stepper = Euler()
    stepper.step(flow, record)
    stepper.step(flow, record)
    return captured


def median_ms(fn, repeats):
    fn()                                  # warm up (compilation, caches)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return 1e3 * statistics.median(times)


def paired(old, new, repeats):
    """Interleaved medians (ms) of two callables: rounds of old, new."""
    t_old, t_new = [], []
    old(), new()
    for _ in range(repeats):
        for fn, acc in ((old, t_old), (new, t_new)):
            start = time.perf_counter()
            fn()
            acc.append(time.perf_counter() - start)
    return 1e3 * statistics.median(t_old), 1e3 * statistics.median(t_new)


_COMPILE = """
import time
t = time.perf_counter()
import numpy as np, scipy.sparse as sp
from mcfbench.running.solver import solve, apply_block
t_import = time.perf_counter() - t
A = sp.eye(6, format="csr") * 2.0
b = np.arange(18.0).reshape(3, 6)
for method in ("bicgstab", "ilu-bicgstab", "direct"):
    solve(A, b, None, method=method)
    solve(sp.eye(18, format="csr"), b, None, method=method)
apply_block(A, b)
print(t_import, time.perf_counter() - t)
"""


def compile_times():
    """``[(import s, import + first calls s)]`` in a fresh interpreter: cold
    (empty numba cache), then cached."""
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        out = []
        for _ in range(2):
            run = subprocess.run([sys.executable, "-c", _COMPILE], env=env, check=True,
                                 capture_output=True, text=True)
            out.append(tuple(float(word) for word in run.stdout.split()))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--no-compile", action="store_true",
                        help="skip the compilation timing")
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})   # one core
    reps = args.repeats

    systems = sphere_systems(args.level)
    A, b, _ = systems[0]
    print(f"level {args.level}: n = {A.shape[0]}, nnz = {A.nnz}, block (3, n)")

    out = np.empty_like(b)
    old, new = paired(lambda: old_apply_block(A, b, out), lambda: apply_block(A, b, out), reps)
    assert np.array_equal(old_apply_block(A, b), apply_block(A, b))   # bitwise
    print(f"block product        old {old:8.3f} ms  new {new:8.3f} ms  ratio {old / new:5.2f}")

    for step, (A, b, x0) in enumerate(systems, start=1):
        for rtol in (1e-9, 1e-12):
            _, it_old, _ = old_bicgstab(A, b, x0, rtol=rtol)
            info = solve(A, b, x0, rtol=rtol)[1]
            assert info.iterations == it_old, (info, it_old)
            old, new = paired(lambda: old_bicgstab(A, b, x0, rtol=rtol),
                              lambda: solve(A, b, x0, rtol=rtol), reps)
            print(f"solve step {step} rtol {rtol:.0e} ({it_old} it)  old {old:8.3f} ms  "
                  f"new {new:8.3f} ms  ratio {old / new:5.2f}")

    A, b, x0 = systems[1]
    per = {}
    for k in (1, 6):
        per[k] = paired(lambda: old_bicgstab(A, b, x0, rtol=1e-30, maxiter=k),
                        lambda: solve(A, b, x0, rtol=1e-30, maxiter=k), max(5, reps // 3))
    old = (per[6][0] - per[1][0]) / 5
    new = (per[6][1] - per[1][1]) / 5
    print(f"one iteration        old {old:8.3f} ms  new {new:8.3f} ms  ratio {old / new:5.2f}")

    print(f"methods on step 2 (rtol 1e-9, median of {max(3, reps // 10)}):")
    for method in METHODS:
        info = solve(A, b, x0, method=method)[1]
        ms = median_ms(lambda: solve(A, b, x0, method=method), max(3, reps // 10))
        print(f"  {method:16s} {ms:9.2f} ms  {info.iterations:3d} it  "
              f"residual {info.residual:.2e}  {info.status}")

    if not args.no_compile:
        (imp, cold), (imp2, cached) = compile_times()
        print(f"first calls in a fresh interpreter: cold cache {cold - imp:.2f} s, "
              f"cached {cached - imp2:.2f} s (plus {imp2:.2f} s to import numpy, scipy, "
              "numba and mcfbench.running.solver)")


if __name__ == "__main__":
    main()
