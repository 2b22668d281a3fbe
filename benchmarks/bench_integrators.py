"""Cost of a time step with each integrator (Euler, BDF2, BDF3), every scheme, in one run.

Per scheme, the shrinking sphere at ``--level`` (Table 3.1's time step) is
stepped by :func:`mcfbench.running.driver.simulate` (the state checks of
every step included, flow construction and error not) with every integrator,
interleaved (in order on even repeats, in reverse on odd ones), after a
warm-up on level 1 so that no compilation is timed. The script prints the
median milliseconds per step of each, their ratios to Euler (target of issue
#22: BDF2 within 10 % of Euler) and the solver iterations per step: one
solve per step with each (BDF3: three at its first step), so a ratio above 1
is the assembly at the extrapolated state (BDF-k assembles at ``X*``, which
the state checks of ``X^n`` cannot share) and the iterations. Usage::

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
    others = names[1:]
    print(f"{'scheme':34s} " + " ".join(f"{n + ' ms':>9s}" for n in names) + " "
          + " ".join(f"{n + '/eu':>8s}" for n in others) + " "
          + " ".join(f"{'it ' + n:>8s}" for n in names) + "  verdict")
    worst = 0.0
    for scheme in args.schemes:
        times = {name: [] for name in names}
        iterations = {}
        for repeat in range(args.repeats):
            for name in (names if repeat % 2 == 0 else names[::-1]):
                ms, its = step_cost(scheme, args.level, name)
                times[name].append(ms)
                iterations[name] = its
        ms = {name: median(times[name]) for name in names}
        ratios = [ms[name] / ms["euler"] for name in others]
        worst = max(worst, ratios[0])
        print(f"{scheme:34s} " + " ".join(f"{ms[n]:9.3f}" for n in names) + " "
              + " ".join(f"{r:8.3f}" for r in ratios) + " "
              + " ".join(f"{iterations[n]:8.1f}" for n in names)
              + f"  {'ok' if ratios[0] <= TARGET else 'above 1.10'}")
    print(f"largest ratio bdf2 / euler: {worst:.3f} (target <= {TARGET})")
    print(footing())


if __name__ == "__main__":
    main()
