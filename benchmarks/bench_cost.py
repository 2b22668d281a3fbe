"""Peak memory and CPU time per step against the number of unknowns: the measurements
behind the size guard (:mod:`mcfbench.running.cost`).

Each (scheme, level) of the sphere runs in a fresh process (one core, one BLAS
thread): a level-1 run first (the kernels loaded, the first calls made: the
fixed part, the peak memory above the resident memory after the imports), then
the level's run (:func:`mcfbench.running.run.run`) and the process's peak
(:func:`mcfbench.storage.memory.peak_rss_mb`) above the resident memory before
it (the part that grows with the mesh). The script prints, per run, the
unknowns (``RunResult.nV``: DDFV's F- plus T-vertices, the mesh vertices
otherwise), the fixed and the growing memory (MB), the CPU seconds per step,
and per kind of :data:`mcfbench.running.cost.COSTS` the fit on the
largest value of its schemes at each level: ``memory = a n^p`` and ``seconds
per step = b n^q`` over the levels whose run rises above the level-1 run's
peak and whose steps are not dominated by fixed costs (``--fit-from``), with
their slopes, and the largest fixed part.
Usage::

    python benchmarks/bench_cost.py [--levels 2 3 4 5] [--fit-from 4]
        [--schemes cotan deturck dual-mdr cotan-redistribute ddfv ddfv-chord-bgn-carried
                   ddfv-chord-redistribute-carried bgn kll]
"""

import argparse
import json
import os
import subprocess
import sys

import numpy as np
from _harness import ROOT, THREAD_VARIABLES, machine_line

from mcfbench.running.cost import cost_class
from mcfbench.studies.beyond.scaling import power_fit

ONE = """
import json, sys
from mcfbench.storage.memory import peak_rss_mb, resident_mb, tune_malloc
tune_malloc()
from mcfbench.running.run import run
start = resident_mb()
run(sys.argv[1], "sphere", 1)                     # the kernels loaded, first calls made
fixed, base = peak_rss_mb() - start, resident_mb()
result, _ = run(sys.argv[1], "sphere", int(sys.argv[2]))
print(json.dumps({"unknowns": result.nV, "fixed_mb": fixed, "memory_mb": peak_rss_mb() - base,
                  "step_seconds": result.cpu_seconds / max(1, result.steps_done),
                  "status": result.status}))
"""


def measure(scheme, level):
    """One run in a fresh process: unknowns, memory above the start (MB), s per step."""
    env = {**os.environ, **dict.fromkeys(THREAD_VARIABLES, "1"), "PYTHONPATH": str(ROOT)}
    out = subprocess.run(["taskset", "-c", str(sorted(os.sched_getaffinity(0))[0]),
                          sys.executable, "-c", ONE, scheme, str(level)],
                         cwd=ROOT, env=env, capture_output=True, text=True, check=True)
    return json.loads(out.stdout.splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[2, 3, 4, 5])
    parser.add_argument("--fit-from", type=int, default=4,
                        help="the memory fit's first level (below it, the fixed part)")
    parser.add_argument("--schemes", nargs="+", default=[
        "cotan", "deturck", "dual-mdr", "cotan-redistribute", "ddfv", "ddfv-chord-bgn-carried",
        "ddfv-chord-redistribute-carried", "bgn", "kll"])
    args = parser.parse_args()
    print(machine_line())
    print(f"{'scheme':32} {'level':>5} {'unknowns':>9} {'fixed MB':>9} {'memory MB':>10} "
          f"{'s/step':>10}")
    rows = []
    for scheme in args.schemes:
        for level in args.levels:
            row = {"scheme": scheme, "level": level, **measure(scheme, level)}
            rows.append(row)
            print(f"{scheme:32} {level:5d} {row['unknowns']:9d} {row['fixed_mb']:9.1f} "
                  f"{row['memory_mb']:10.1f} "
                  f"{row['step_seconds']:10.3g}  {row['status']}", flush=True)
    for name in sorted({cost_class(row["scheme"]) for row in rows}):
        mine = [row for row in rows if cost_class(row["scheme"]) == name]
        levels = sorted({row["level"] for row in mine})
        worst = {key: [max(row[key] for row in mine if row["level"] == level)
                       for level in levels] for key in ("unknowns", "memory_mb", "step_seconds", "fixed_mb")}
        big = [k for k, level in enumerate(levels) if level >= args.fit_from]
        memory = power_fit(np.take(worst["unknowns"], big), np.take(worst["memory_mb"], big))
        step = power_fit(np.take(worst["unknowns"], big), np.take(worst["step_seconds"], big))
        print(f"{name}: memory_mb = {memory[0]:.4g} n^{memory[1]:.3f}, step_seconds = "
              f"{step[0]:.4g} n^{step[1]:.3f} (levels >= {args.fit_from}) "
              f"(the largest of {sorted({row['scheme'] for row in mine})} at each level), "
              f"fixed part {max(worst['fixed_mb']):.0f} MB")


if __name__ == "__main__":
    main()
