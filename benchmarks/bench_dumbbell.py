"""What the matrix's series cost on one problem and level (issue 32: the dumbbell's level 3).

Each series of the matrix (``config/config.yaml``'s ``matrix``: every scheme of
the registry and those of ``with_integrators``) runs as the matrix's job runs
it (:func:`mcfbench.running.run.framed_run`, BiCGStab at the matrix's tolerance,
the scheme's robust solver for a run that ends with a solver status), each in a
fresh process on one core with one BLAS thread, niced, one after the other.
Printed per series: status, steps done, CPU seconds of the run (and of a robust
re-run), CPU seconds a step, the shared solver's iterations a step, and for the
DDFV tangential motions the solves' factorisations and CG iterations; at the end
the sum. With ``--steps k`` only the first ``k`` steps are timed (the stop step of
a full run is then not known); ``--solver`` another method of the shared solver
(``kept-ilu-bicgstab``: the anisotropic sphere's in the matrix).

Usage::

    python benchmarks/bench_dumbbell.py [--problem dumbbell] [--level 3] [--steps 0]
        [--schemes ddfv-chord-bgn-carried ...] [--solver bicgstab] [--json out.jsonl]
"""

import argparse
import json
import os
import subprocess
import sys

from _harness import ROOT, THREAD_VARIABLES, machine_line

ONE = """
import json, sys
from dataclasses import replace
from mcfbench.storage.memory import tune_malloc
tune_malloc()
from mcfbench.running.problems import get_problem
from mcfbench.running.run import framed_run, problem_mesh
from mcfbench.running.schemes import get_scheme
from mcfbench.running.solver import Solver
name, problem, level, steps = sys.argv[1], get_problem(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4])
method = sys.argv[5]
scheme, integrator = get_scheme(name), None
flows = []
class Capture:
    def __getattr__(self, key):
        return getattr(scheme, key)
    def make(self, *args, **kwargs):
        flows.append(scheme.make(*args, **kwargs))
        return flows[-1]
solver = Solver(method)
mesh = problem_mesh(problem, level)
tau = problem.tau(level, mesh)
options = {"t_final": steps * tau} if steps else {}
result, _, robust = framed_run(Capture(), problem, level, solver=solver, mesh=mesh,
                               robust=replace(solver, method=scheme.robust_solver), **options)
motion = getattr(flows[-1], "_motion", None)
print(json.dumps({"scheme": name, "status": result.status, "steps": result.steps_done,
                  "of": result.N, "cpu": result.cpu_seconds, "metrics": result.metrics,
                  "solves": result.iterations,
                  "min_angle": result.min_angle, "t_end": result.t_end,
                  "robust_status": robust.status if robust else "",
                  "robust_cpu": robust.cpu_seconds if robust else 0.0,
                  "factorisations": motion.factorisations if motion else None,
                  "iterations": motion.iterations if motion else None}))
"""


def series():
    """The matrix's series of the default config: every scheme, then ``with_integrators``."""
    import yaml

    from mcfbench.running.schemes import SCHEMES

    section = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["matrix"]
    names = list(SCHEMES) if section.get("schemes", "all") == "all" else section["schemes"]
    return names + [f"{s}@{integrator}" for integrator, schemes in
                    (section.get("with_integrators") or {}).items() for s in schemes]


def measure(scheme, problem, level, steps, method="bicgstab"):
    """One series' run in a fresh, niced process on one core: its JSON line as a dict."""
    env = {**os.environ, **dict.fromkeys(THREAD_VARIABLES, "1"), "PYTHONPATH": str(ROOT)}
    core = str(sorted(os.sched_getaffinity(0))[0])
    out = subprocess.run(["nice", "taskset", "-c", core, sys.executable, "-c", ONE, scheme,
                          problem, str(level), str(steps), method],
                         cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problem", default="dumbbell")
    parser.add_argument("--level", type=int, default=3)
    parser.add_argument("--steps", type=int, default=0, help="time only these steps (0: all)")
    parser.add_argument("--schemes", nargs="*", help="default: the matrix's series")
    parser.add_argument("--solver", default="bicgstab", help="the shared solver's method")
    parser.add_argument("--json", help="also append every series' line to this file")
    args = parser.parse_args()
    print(machine_line())
    total = 0.0
    print(f"{'series':36s} {'status':12s} {'steps':>9s} {'CPU s':>8s} {'s/step':>7s} "
          f"{'it/step':>7s} {'robust':>14s} {'fact.':>5s} {'CG it.':>6s}")
    for scheme in args.schemes or series():
        row = measure(scheme, args.problem, args.level, args.steps, args.solver)
        total += row["cpu"] + row["robust_cpu"]
        robust = f"{row['robust_status']} {row['robust_cpu']:.1f}" if row["robust_status"] else ""
        print(f"{scheme:36s} {row['status']:12s} {row['steps']:4d}/{row['of']:4d} "
              f"{row['cpu']:8.1f} {row['cpu'] / max(1, row['steps']):7.3f} "
              f"{row['solves'] / max(1, row['steps']):7.1f} {robust:>14s} "
              f"{row['factorisations'] or '':>5} {row['iterations'] or '':>6}", flush=True)
        if args.json:
            with open(args.json, "a") as f:
                f.write(json.dumps(row) + "\n")
    print(f"total CPU s: {total:.1f} ({machine_line()})")


if __name__ == "__main__":
    main()
