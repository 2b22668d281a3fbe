"""Cost of a step of ``cotan-intrinsic`` against ``cotan`` on the sphere, levels 3-5, in one run.

Per level, the shrinking sphere (Table 3.1's time step, to ``t = 0.08`` or
``--steps`` steps; another ``--problem``: its mesh and time step; the sphere
stays Delaunay, the catenoid and the Angenent torus take one round of flips
a step) is stepped by :func:`mcfbench.running.driver.simulate`
(state checks included, flow construction not) with the two schemes,
interleaved (``cotan`` first on even repeats, last on odd ones), after a
warm-up on level 1 so that no compilation is timed. Prints the median
milliseconds per step and per assembly (``flow.timings["assembly"]``: for
``cotan-intrinsic`` the intrinsic Delaunay triangulation's Laplacian and mass,
from the mesh where it is that triangulation or one round of flips away, else
from ``robust_laplacian.mesh_laplacian``, and the row scaling) of
each, and their ratios, measured in this run. Usage::

    python benchmarks/bench_intrinsic.py [--levels 3 4 5] [--repeats 5] [--steps 32]
        [--problem sphere]
"""

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402

from _harness import footing, machine_line, median, one_core  # noqa: E402

from mcfbench.running.driver import simulate  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.run import problem_mesh  # noqa: E402
from mcfbench.running.schemes import get_scheme  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402
from mcfbench.storage.memory import tune_malloc  # noqa: E402

SCHEMES = ("cotan", "cotan-intrinsic")


def step_cost(scheme, level, steps, problem="sphere"):
    """``(ms per step, ms of assembly per step)`` of one run of ``problem`` at ``level``."""
    problem = get_problem(problem)
    V, F = problem_mesh(problem, level)
    tau = problem.tau(level, (V, F))
    steps = min(steps, problem.time_steps(tau))
    flow = get_scheme(scheme).make(V, F, tau)
    traj = simulate(flow, steps, solver=Solver(), save_every=0)
    if not traj.ok:
        raise RuntimeError(f"{scheme}: {traj.message}")
    return 1e3 * traj.wall_seconds / steps, 1e3 * flow.timings["assembly"] / steps


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[3, 4, 5])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=32)
    parser.add_argument("--problem", default="sphere", help="a problem of the registry")
    args = parser.parse_args(argv)
    tune_malloc()
    one_core()
    print(machine_line())
    for scheme in SCHEMES:                            # warm-up: compilation, caches
        step_cost(scheme, 1, 2, args.problem)
    print(f"{args.problem}, ms per step and per assembly (median of {args.repeats}, "
          f"at most {args.steps} steps)")
    print(f"{'level':>5s} {'cotan':>8s} {'intrinsic':>9s} {'ratio':>6s} "
          f"{'asm cotan':>9s} {'asm intr':>9s} {'ratio':>7s}")
    for level in args.levels:
        step = {s: [] for s in SCHEMES}
        assembly = {s: [] for s in SCHEMES}
        for repeat in range(args.repeats):
            for scheme in (SCHEMES if repeat % 2 == 0 else SCHEMES[::-1]):
                ms, asm = step_cost(scheme, level, args.steps, args.problem)
                step[scheme].append(ms)
                assembly[scheme].append(asm)
        s0, s1 = (median(step[s]) for s in SCHEMES)
        a0, a1 = (median(assembly[s]) for s in SCHEMES)
        print(f"{level:5d} {s0:8.3f} {s1:9.3f} {s1 / s0:6.1f} {a0:9.3f} {a1:9.3f} "
              f"{a1 / a0:7.1f}")
    print(footing())


if __name__ == "__main__":
    main()
