"""Cost of a time step with each integrator (Euler, BDF2), every scheme, in one run.

Per scheme, the shrinking sphere at ``--level`` (Table 3.1's time step) is
stepped by :func:`mcfbench.running.driver.simulate` (the state checks of
every step included, flow construction and error not) with ``euler`` and
with ``bdf2``, interleaved (Euler first on even repeats, BDF2 first on odd
ones), after a warm-up on level 1 so that no compilation is timed. The
script prints the median milliseconds per step of each, their ratio
(target of issue #22: BDF2 within 10 % of Euler) and the solver
iterations per step: one solve per step with both, so a ratio above 1
is the assembly at the extrapolated state (BDF2 assembles at
``2 X^n - X^{n-1}``, which the state checks of ``X^n`` cannot share) and
the iterations. Usage::

    python benchmarks/bench_integrators.py [--level 4] [--repeats 5] [--schemes ddfv cotan]
"""

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402

from _harness import footing, machine_line, median, one_core  # noqa: E402

from mcfbench.geometry.spheres import icosphere  # noqa: E402
from mcfbench.running.driver import simulate  # noqa: E402
from mcfbench.running.integrators import INTEGRATORS  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.schemes import SCHEMES, get_scheme  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402
from mcfbench.storage.memory import tune_malloc  # noqa: E402

TARGET = 1.10


def step_cost(scheme, level, integrator):
    """``(ms per step, iterations per step)`` of one run of the sphere at ``level``."""
    sphere = get_problem("sphere")
    V, F = icosphere(level)
    tau = sphere.tau(level)
    steps = sphere.time_steps(tau)
    traj = simulate(get_scheme(scheme).make(V, F, tau), steps, solver=Solver(),
                    integrator=integrator, save_every=0)
    if not traj.ok:
        raise RuntimeError(f"{scheme} with {integrator}: {traj.message}")
    return 1e3 * traj.wall_seconds / steps, traj.iterations.mean()


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=4)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--schemes", nargs="+", default=list(SCHEMES))
    args = parser.parse_args(argv)
    tune_malloc()
    one_core()
    print(machine_line())
    names = list(INTEGRATORS)
    for scheme in args.schemes:                       # warm-up: compilation, caches
        for integrator in names:
            step_cost(scheme, 1, integrator)
    print(f"sphere level {args.level}, ms per step (median of {args.repeats}), "
          f"iterations per step")
    print(f"{'scheme':34s} {'euler ms':>9s} {'bdf2 ms':>9s} {'ratio':>6s} "
          f"{'it euler':>8s} {'it bdf2':>8s}  verdict")
    worst = 0.0
    for scheme in args.schemes:
        times = {name: [] for name in names}
        iterations = {}
        for repeat in range(args.repeats):
            for name in (names if repeat % 2 == 0 else names[::-1]):
                ms, its = step_cost(scheme, args.level, name)
                times[name].append(ms)
                iterations[name] = its
        euler, bdf2 = median(times["euler"]), median(times["bdf2"])
        ratio = bdf2 / euler
        worst = max(worst, ratio)
        print(f"{scheme:34s} {euler:9.3f} {bdf2:9.3f} {ratio:6.3f} "
              f"{iterations['euler']:8.1f} {iterations['bdf2']:8.1f}  "
              f"{'ok' if ratio <= TARGET else 'above 1.10'}")
    print(f"largest ratio bdf2 / euler: {worst:.3f} (target <= {TARGET})")
    print(footing())


if __name__ == "__main__":
    main()
