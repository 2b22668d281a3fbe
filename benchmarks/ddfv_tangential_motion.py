"""DDFV's F-vertices with BGN's or MDR's tangential motion (``ddfv/tangential_motion.py``)
against ``ddfv-chord-carried``: the real meshes and the sphere (issue 30).

    python benchmarks/ddfv_tangential_motion.py                  # all three parts
    python benchmarks/ddfv_tangential_motion.py --parts sphere --schemes ddfv-chord-bgn-carried

Parts:

* ``problems``: the registry's real-mesh problems ``real_<mesh>`` (level 0; level 1 of
  the two smallest, nut and rounded_cube): status, steps, smallest angle at the end
  (the last sampled level), the largest relative area and volume errors against the
  references;
* ``long``: the committed meshes as a user's mesh (``tau = 0.1 h^2``, 40 steps, the
  setting of ``ddfv/README.md``'s real-mesh table): status, steps, area end / start,
  smallest angle at the end;
* ``sphere``: the Table 3.1 setting, levels 1-3: the L2 error (3.2) and its EOC;
* ``catenoid``: the cylinder between two fixed circles relaxing to the catenoid,
  levels 1-2: the neck error and its EOC (a fixed boundary);
* ``step``: the cost of a step (not a default part): per scheme, the CPU ms a step of
  the run and the wall ms of the flow's phases (``Flow.timings``: ``tangential``
  for BGN and MDR, ``potential`` for the redistribution), the factorisations and
  CG iterations a step of the motion's (or the potential's) kept factor, at
  ``--problem`` and ``--level`` (default catenoid 3), ``--steps`` steps (default
  the whole run), after a warm-up of 3 steps at level 1; one core, one thread:

      python benchmarks/ddfv_tangential_motion.py --parts step --level 3 \
          --schemes ddfv-chord-carried ddfv-chord-bgn-carried ddfv-chord-mdr-carried \
          ddfv-chord-redistribute-carried

The runs are those of the command line (:func:`mcfbench.running.run.run`, the sparse LU).
"""

import argparse
import os
import sys
import time

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402

from mcfbench.geometry import metrics  # noqa: E402
from mcfbench.geometry.committed_meshes import read_committed_mesh  # noqa: E402
from mcfbench.running.problems import Problem  # noqa: E402
from mcfbench.running.run import run  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402

SCHEMES = ("ddfv-chord-carried", "ddfv-chord-bgn-carried", "ddfv-chord-mdr-carried")
MESHES = ("nut", "rounded_cube", "spot", "blub")
PROBLEM_LEVELS = {"nut": (0, 1), "rounded_cube": (0, 1), "spot": (0,), "blub": (0,)}


def _angle_at_end(result):
    return result.series["min_angle"][-1] if result.series.get("min_angle") else np.nan


def problems(schemes):
    print("| problem | level | scheme | status | steps | min angle at end (deg) | "
          "area error | volume error |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for mesh in MESHES:
        for level in PROBLEM_LEVELS[mesh]:
            for scheme in schemes:
                result, _ = run(scheme, f"real_{mesh}", level, solver=Solver(method="direct"))
                m = result.metrics
                area = m.get("area_error", np.nan)
                volume = m.get("volume_error", np.nan)
                print(f"| real_{mesh} | {level} | {scheme} | {result.status} | "
                      f"{result.steps_done}/{result.N} | {_angle_at_end(result):.3g} | "
                      f"{area:.3e} | {volume:.3e} |", flush=True)


def long_runs(schemes, steps=40):
    print("| mesh (initial min angle) | scheme | status | steps | area end/start | "
          "min angle at end (deg) |")
    print("| --- | --- | --- | --- | --- | --- |")
    for mesh in MESHES:
        V, F = read_committed_mesh(mesh)
        start = metrics.min_angle(V, F)
        area_0 = metrics.area(V, F)
        for scheme in schemes:
            result, traj = run(scheme, Problem.user_mesh(mesh, steps, 0.1), 0, mesh=(V, F),
                               solver=Solver(method="direct"))
            end = traj.frames["vertices"][-1]
            print(f"| {mesh} ({start:.3g}) | {scheme} | {result.status} | "
                  f"{result.steps_done} | {metrics.area(end, F) / area_0:.3f} | "
                  f"{metrics.min_angle(end, F):.3g} |", flush=True)


def sphere(schemes, levels=(1, 2, 3)):
    print("| scheme | L2 error, levels " + ", ".join(map(str, levels)) + " | EOC |")
    print("| --- | --- | --- |")
    for scheme in schemes:
        errors = []
        for level in levels:
            result, _ = run(scheme, "sphere", level)
            errors.append(result.metrics["l2_error"])
        eoc = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
        print(f"| {scheme} | {', '.join(f'{e:.4e}' for e in errors)} | "
              f"{', '.join(f'{x:.3f}' for x in eoc)} |", flush=True)


def catenoid(schemes, levels=(1, 2)):
    print("| scheme | neck error, levels " + ", ".join(map(str, levels)) + " | EOC |")
    print("| --- | --- | --- |")
    for scheme in schemes:
        errors = [run(scheme, "catenoid", level)[0].metrics["neck_error"] for level in levels]
        eoc = np.log2(np.abs(np.array(errors[:-1]) / np.array(errors[1:])))
        print(f"| {scheme} | {', '.join(f'{e:.4e}' for e in errors)} | "
              f"{', '.join(f'{x:.3f}' for x in eoc)} |", flush=True)


def step(schemes, problem="catenoid", level=3, steps=None):
    from _harness import harness_run, machine_line, one_core

    one_core()
    print(f"step: {machine_line()}; {problem} level {level}")
    print("| scheme | steps | CPU ms/step | wall ms/step by phase | factorisations | "
          "CG iterations/step |")
    print("| --- | --- | --- | --- | --- | --- |")
    for scheme in schemes:
        harness_run(scheme, 1, problem=problem, steps=3)                 # warm-up
        clock = time.process_time()
        result, flow = harness_run(scheme, level, problem=problem, steps=steps)
        cpu, n = time.process_time() - clock, result.steps_done
        phases = ", ".join(f"{k} {1e3 * v / n:.3f}" for k, v in flow.timings.items() if v)
        solver = flow._motion or flow._potential
        kept = ("-", "-") if solver is None else (solver.factorisations,
                                                  f"{solver.iterations / n:.2f}")
        print(f"| {scheme} | {n} | {1e3 * cpu / n:.3f} | {phases} | {kept[0]} | {kept[1]} |",
              flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parts = {"problems": problems, "long": long_runs, "sphere": sphere, "catenoid": catenoid,
             "step": step}
    parser.add_argument("--parts", nargs="+", default=[p for p in parts if p != "step"],
                        choices=list(parts))
    parser.add_argument("--schemes", nargs="+", default=list(SCHEMES))
    parser.add_argument("--problem", default="catenoid", help="of the step part")
    parser.add_argument("--level", type=int, default=3, help="of the step part")
    parser.add_argument("--steps", type=int, help="of the step part (default: the run's)")
    args = parser.parse_args()
    for part in args.parts:
        if part == "step":
            step(args.schemes, args.problem, args.level, args.steps)
        else:
            parts[part](args.schemes)


if __name__ == "__main__":
    main()
