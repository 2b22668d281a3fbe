"""Orders of ``kll`` on the sphere (position, nu, H) and its cost per step against ``cotan``.

Orders: the Table 3.1 setting (icosphere level k, ``tau = 0.04 / 4^(k-1)``, to
``t = 0.08``), each integrator asked for, BiCGStab rtol 1e-10: the errors at
the final time of :func:`mcfbench.geometry.exact.sphere_state_errors` (position,
normal, mean curvature), the space-time L2 error (3.2) of the position
(:class:`mcfbench.geometry.exact.SphereL2Error`, the Table 3.1 measure) and their
EOC, and BiCGStab's iterations per step.

Cost: per level, the sphere stepped by :func:`mcfbench.running.driver.simulate`
(state checks included, flow construction not; ``--steps`` steps at most) with
``cotan`` and ``kll`` (Euler, ``Solver(method)``, rtol 1e-9; ``--methods``:
BiCGStab, the matrix's footing on the sphere, and/or the sparse LU ``direct``,
its method on the real meshes), interleaved (``cotan`` first on even repeats,
last on odd ones), after a warm-up on level 1 so that no compilation is timed;
the median milliseconds per step of each and their ratio, measured in this run.

Block solve: for each ``--solves problem:level``, the first step's (KL6) of
``kll`` solved as one (7n, 7n) matrix (``A.tocsr()``, what the solver saw before
the block solve) and by blocks (``A`` itself: ``S`` for four right-hand sides,
then (KL7)), with the sparse LU and with BiCGStab, and ``cotan``'s system with
the same method; median milliseconds of ``--repeats`` interleaved solves and the
largest difference of the two solutions. Usage::

    python benchmarks/bench_kll.py [--levels 1 2 3 4] [--integrators euler bdf2 bdf3]
                                   [--repeats 5] [--steps 32] [--methods bicgstab direct]
                                   [--solves real_spot:1 sphere:5]
"""

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

from _harness import footing, machine_line, median, one_core  # noqa: E402

from mcfbench.geometry.exact import SphereL2Error, eoc, sphere_state_errors  # noqa: E402
from mcfbench.geometry.spheres import icosphere  # noqa: E402
from mcfbench.running.driver import simulate  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.schemes import get_scheme, joined_name  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402
from mcfbench.storage.memory import tune_malloc  # noqa: E402

SCHEMES = ("cotan", "kll")
QUANTITIES = ("position", "normal", "curvature", "L2 (3.2)")


def sphere_errors(integrator, level):
    """``(errors by QUANTITIES, iterations per step)`` of ``kll`` on the level-``level``
    sphere to ``t = 0.08``."""
    sphere = get_problem("sphere")
    V, F = icosphere(level)
    tau = sphere.tau(level)
    steps = sphere.time_steps(tau)
    flow = get_scheme(joined_name("kll", integrator)).make(V, F, tau)
    l2 = SphereL2Error()
    traj = simulate(flow, steps, solver=Solver(rtol=1e-10), save_every=0, observers=[l2],
                    integrator=integrator)
    if not traj.ok:
        raise RuntimeError(f"kll@{integrator}, level {level}: {traj.message}")
    errors = sphere_state_errors(flow.vertices, flow.l2_weights, steps * tau,
                                 normals=flow.nu, curvature=flow.H)
    return [*errors.values(), l2.value], traj.iterations.sum() / steps


def step_cost(scheme, level, steps, method="bicgstab"):
    """Milliseconds per step of one run of the sphere at ``level``."""
    sphere = get_problem("sphere")
    V, F = icosphere(level)
    tau = sphere.tau(level)
    steps = min(steps, sphere.time_steps(tau))
    traj = simulate(get_scheme(scheme).make(V, F, tau), steps, solver=Solver(method),
                    save_every=0)
    if not traj.ok:
        raise RuntimeError(f"{scheme}: {traj.message}")
    return 1e3 * traj.wall_seconds / steps


def solve_costs(problem, level, method, repeats):
    """``({"kll 7n": ms, "kll blocks": ms, "cotan": ms}, difference)`` of the first
    step's solves (module docstring)."""
    problem = get_problem(problem)
    V, F = problem.mesh(level)
    tau = problem.tau(level, (V, F))
    systems = {}
    for scheme in SCHEMES:
        flow = get_scheme(scheme).make(V, F, tau)
        systems[scheme] = (*flow.system(), flow.state.copy())
    A, b, x0 = systems["kll"]
    cases = {"kll 7n": (A.tocsr(), b, x0), "kll blocks": systems["kll"],
             "cotan": systems["cotan"]}
    solver, ms, solutions = Solver(method), {c: [] for c in cases}, {}
    for repeat in range(repeats):
        for case in (cases if repeat % 2 == 0 else list(cases)[::-1]):
            clock = time.perf_counter()
            solutions[case] = solver(*cases[case])[0]
            ms[case].append(1e3 * (time.perf_counter() - clock))
    difference = np.abs(solutions["kll 7n"] - solutions["kll blocks"]).max()
    return {c: median(t) for c, t in ms.items()}, difference, len(V)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4])
    parser.add_argument("--integrators", nargs="+", default=["euler", "bdf2", "bdf3"])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--steps", type=int, default=32)
    parser.add_argument("--methods", nargs="+", default=["bicgstab"],
                        choices=["bicgstab", "direct"])
    parser.add_argument("--solves", nargs="*", default=[], metavar="PROBLEM:LEVEL")
    args = parser.parse_args(argv)
    tune_malloc()
    one_core()
    print(machine_line())
    for integrator in args.integrators:
        rows = [sphere_errors(integrator, level) for level in args.levels]
        orders = [eoc([row[0][q] for row in rows], levels=args.levels)
                  for q in range(len(QUANTITIES))]
        print(f"kll@{integrator}: errors at t = 0.08 (EOC), iterations per step")
        print(f"{'level':>5s} " + " ".join(f"{q:>18s}" for q in QUANTITIES) + f" {'it':>5s}")
        for k, (level, (errors, iterations)) in enumerate(zip(args.levels, rows)):
            cells = [f"{e:.4e} ({o[k]:5.2f})" for e, o in zip(errors, orders)]
            print(f"{level:5d} " + " ".join(f"{c:>18s}" for c in cells) + f" {iterations:5.1f}")
    for scheme in SCHEMES:                            # warm-up: compilation, caches
        for method in args.methods:
            step_cost(scheme, 1, 2, method)
    for method in args.methods:
        print(f"sphere, Euler, {method}, ms per step (median of {args.repeats}, at most "
              f"{args.steps} steps)")
        print(f"{'level':>5s} {'cotan':>8s} {'kll':>8s} {'ratio':>6s}")
        for level in args.levels:
            step = {s: [] for s in SCHEMES}
            for repeat in range(args.repeats):
                for scheme in (SCHEMES if repeat % 2 == 0 else SCHEMES[::-1]):
                    step[scheme].append(step_cost(scheme, level, args.steps, method))
            s0, s1 = (median(step[s]) for s in SCHEMES)
            print(f"{level:5d} {s0:8.3f} {s1:8.3f} {s1 / s0:6.1f}")
    for case in args.solves:
        problem, level = case.rsplit(":", 1)
        for method in args.methods:
            ms, difference, n = solve_costs(problem, int(level), method, args.repeats)
            print(f"{problem} level {level} ({n} vertices), {method}, ms per solve (median "
                  f"of {args.repeats}): " + ", ".join(f"{c} {t:.1f}" for c, t in ms.items())
                  + f"; 7n / blocks {ms['kll 7n'] / ms['kll blocks']:.1f}; solutions differ "
                  f"by {difference:.1e}")
    print(footing())


if __name__ == "__main__":
    main()
