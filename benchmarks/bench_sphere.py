"""Time the sphere experiment of Table 3.1 (levels 1-5), one core.

Prints, per level, the median wall time over repeats with its split into
geometry (diamond quantities, covolumes, checks), assembly, solve and the
rest (T monitor, L2 error, set-up), and the time per step and unknown.
Every number comes from this one run: compare ratios, not absolute
seconds, across machines or runs (the machine is shared and noisy).

    python benchmarks/bench_sphere.py [--levels 1 2 3 4 5] [--repeats 3]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

from ddfv import SphereL2Error, icosphere, simulate  # noqa: E402
from ddfv.sphere import T_FINAL, level_time_step  # noqa: E402


def time_level(level):
    V, F = icosphere(level)
    tau = level_time_step(level)
    steps = int(round(T_FINAL / tau))
    start = time.perf_counter()
    traj = simulate(V, F, tau, steps, save_every=0, observer=SphereL2Error())
    wall = time.perf_counter() - start
    return wall, traj.timings, steps, len(V) + len(F), int(traj.iterations.sum())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})   # one core
    print(f"{'level':>5} {'nV':>6} {'steps':>5} {'iter':>5} {'wall s':>7} "
          f"{'geom':>6} {'assem':>6} {'solve':>6} {'other':>6} {'us/(step*nV)':>12}")
    total = 0.0
    for level in args.levels:
        runs = [time_level(level) for _ in range(args.repeats)]
        wall = statistics.median(r[0] for r in runs)
        phases = {k: statistics.median(r[1][k] for r in runs) for k in runs[0][1]}
        _, _, steps, nV, iterations = runs[0]
        other = wall - sum(phases.values())
        total += wall
        print(f"{level:5d} {nV:6d} {steps:5d} {iterations:5d} {wall:7.3f} "
              + " ".join(f"{phases[k] / wall:6.1%}" for k in ("geometry", "assembly", "solve"))
              + f" {other / wall:6.1%} {1e6 * wall / (steps * nV):12.3f}")
    print(f"levels {args.levels}: {total:.2f} s wall in total (medians of {args.repeats})")


if __name__ == "__main__":
    main()
