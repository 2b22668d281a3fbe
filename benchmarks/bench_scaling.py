"""Every scheme family's step and peak memory to a million vertices (issue #46, item 1):
the slopes above the last-level cache, each step against its bound, the size guard's
estimate against the measured peak.

The meshes (``--meshes``): the sphere's icosphere levels (``sphere:6``, ``sphere:7``,
``sphere:8``: 40 962, 163 842 and 655 362 vertices) and a committed real mesh refined by
Loop as the real-mesh problems refine it (``real_bob:6``:
:func:`mcfbench.geometry.committed_meshes.real_mesh`, bob's 250 vertices after six Loop
steps, 1 024 000 vertices), each with its problem's time step (the sphere's ``0.04 /
4^(k-1)``, the real mesh's ``0.1 h_0^2 / 4^k``).

Each (scheme, mesh) runs in a fresh process (one core, one BLAS and numba thread,
malloc tuned), so that its peak resident memory is its own: a level-1 sphere run first
(the kernels loaded), then the mesh built and renumbered as a run renumbers it
(:mod:`mcfbench.running.locality`), the flow made and stepped by
``bench_bound.measure`` (one warm-up step, then ``--steps`` timed ones, the median CPU
ms; the solver's iterations; the bytes and flops of ``bench_bound.py``'s counting
model). Printed per run: the vertices and unknowns (DDFV's F- plus T-vertices), ms per
step, iterations per step, ``bound = max(bytes / B, flops / F)`` with ``B`` (STREAM
triad) and ``F`` measured in this parent process, the ratio, the peak resident memory
above the child's after its imports (what :func:`mcfbench.running.cost.estimate`
estimates: the same quantity) and the estimate beside it, the level-1 run's part of it
(fixed) and the peak above the resident memory after the level-1 run (the part that
grows with the mesh, as ``bench_cost.py`` splits it). Then per scheme the log-log
slopes of the CPU per step (and of it over the iterations per step, at least one: the
real mesh's steps take more iterations than the sphere's, and their number moves with
the level) and of the growing memory against the vertices, fitted per problem on its
three largest meshes measured (:func:`mcfbench.studies.beyond.scaling.power_fit`): the
sphere's levels 6-8 and the real mesh's levels 4-6 (64 000, 256 000, 1 024 000 vertices).

The machine is shared: the load average is printed with every run (and the run's
numbers as a JSON line, kept if the script is stopped before its table); ``--repeats``
runs each (scheme, mesh) again, the meshes in reverse order, keeping the fastest step.

Usage::

    python benchmarks/bench_scaling.py [--schemes cotan bgn ...]
        [--meshes sphere:6 sphere:7 sphere:8 real_bob:6] [--repeats 1] [--triad-mb 512]
"""

import argparse
import json
import os
import subprocess
import sys
import time

from _harness import ROOT, THREAD_VARIABLES, footing, machine_line, one_core

SCHEMES = ["cotan", "cmcf", "bgn", "mdr", "dual-mdr", "deturck", "kll",
           "ddfv-chord-carried", "cotan-redistribute", "ddfv-chord-redistribute-carried"]
"""Every scheme family: the vertex schemes (cotan, cmcf), the coupled systems (BGN, MDR,
dual-MDR, DeTurck), KLL's blocks, DDFV, and both families' redistribution (a kept
factorisation)."""
MESHES = ["sphere:6", "sphere:7", "sphere:8", "real_bob:4", "real_bob:5", "real_bob:6"]
STEPS = {"sphere:6": 8, "sphere:7": 4}
"""Timed steps per mesh (after the warm-up step); 3 for the others."""

CHILD = """
import json, sys
sys.path.insert(0, sys.argv[4])
from pathlib import Path
from mcfbench.storage.memory import resident_mb, tune_malloc
tune_malloc()

def peak_rss_mb():   # this process's own high-water mark: getrusage's ru_maxrss keeps
    status = Path("/proc/self/status").read_text()   # the parent's resident memory at fork
    return int(status.split("VmHWM:")[1].split()[0]) / 1024

import bench_bound
from mcfbench.running.cost import estimate
from mcfbench.running.problems import get_problem
from mcfbench.running.schemes import get_scheme
start = resident_mb()
scheme, problem, level, steps = sys.argv[1], get_problem(sys.argv[2]), int(sys.argv[3]), \
    int(sys.argv[5])
bench_bound.measure(scheme, 1, 2)                 # the kernels loaded, first calls made
fixed, base = peak_rss_mb() - start, resident_mb()
mesh = problem.mesh(level)
unknowns = len(mesh[0]) + (len(mesh[1]) if get_scheme(scheme).extra_points else 0)
ms, it, nbytes, flops, nv = bench_bound.measure(scheme, level, steps, mesh=mesh,
                                                order="harness", tau=problem.tau(level, mesh))
print(json.dumps({"ms": ms, "iterations": it, "bytes": nbytes, "flops": flops,
                  "vertices": nv, "unknowns": unknowns, "peak_mb": peak_rss_mb() - start,
                  "fixed_mb": fixed, "growing_mb": peak_rss_mb() - base,
                  "estimate_mb": estimate(scheme, unknowns, 1).memory_mb}))
"""


def run_child(scheme, mesh, steps):
    """One (scheme, mesh) in a fresh process pinned to this one's core: the child's
    JSON line (module docstring)."""
    problem, level = mesh.split(":")
    env = {**os.environ, **dict.fromkeys(THREAD_VARIABLES, "1"), "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", CHILD, scheme, problem, level,
                          str(ROOT / "benchmarks"), str(steps)],
                         cwd=ROOT, env=env, capture_output=True, text=True)
    if out.returncode:
        last = (out.stderr.strip().splitlines() or [f"ended by signal {-out.returncode}"
                                                    if out.returncode < 0 else "no message"])
        raise RuntimeError(f"{scheme} on {mesh}: exit {out.returncode}: {last[-1]}")
    return json.loads(out.stdout.splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--schemes", nargs="+", default=SCHEMES)
    parser.add_argument("--meshes", nargs="+", default=MESHES,
                        help="PROBLEM:LEVEL, e.g. sphere:8 real_bob:6")
    parser.add_argument("--steps", type=int, default=None,
                        help=f"timed steps (default per mesh: {STEPS}, else 3)")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--triad-mb", type=float, default=512.0)
    args = parser.parse_args(argv)
    one_core()
    from bench_bound import flop_rate, stream_bandwidth

    from mcfbench.storage.memory import tune_malloc
    from mcfbench.studies.beyond.scaling import power_fit

    tune_malloc()
    print(machine_line())
    B, F = stream_bandwidth(args.triad_mb, 10), flop_rate()
    print(f"B = {B / 1e9:.2f} GB/s (STREAM triad, 3 x {args.triad_mb:g} MB, best of 10); "
          f"F = {F / 1e9:.1f} GFlop/s (matmul 2000^2, one thread)", flush=True)
    best = {}
    for repeat in range(args.repeats):
        for scheme in args.schemes:
            for mesh in args.meshes if repeat % 2 == 0 else args.meshes[::-1]:
                steps = args.steps or STEPS.get(mesh, 3)
                load = os.getloadavg()[0]
                try:
                    row = run_child(scheme, mesh, steps)
                except RuntimeError as error:
                    print(f"  [{time.strftime('%H:%M:%S')}] {error}", flush=True)
                    continue
                row["load"] = load
                old = best.get((scheme, mesh))
                best[(scheme, mesh)] = row if old is None or row["ms"] < old["ms"] else old
                print(f"  [{time.strftime('%H:%M:%S')} load {load:.2f}] {scheme} {mesh}: "
                      f"{row['ms']:.1f} ms/step, peak {row['peak_mb']:.0f} MB "
                      f"{json.dumps({'scheme': scheme, 'mesh': mesh, **row})}", flush=True)
    print(f"\n{machine_line()}")
    print(f"{'scheme':>32} {'mesh':>11} {'vertices':>9} {'unknowns':>9} {'ms/step':>9} "
          f"{'it/step':>7} {'bound ms':>9} {'ratio':>6} {'peak MB':>8} {'est. MB':>8} "
          f"{'fixed MB':>8} {'grows MB':>8} {'load':>5}")
    for scheme in args.schemes:
        for mesh in args.meshes:
            if (scheme, mesh) not in best:
                print(f"{scheme:>32} {mesh:>11}  (no result)")
                continue
            r = best[(scheme, mesh)]
            bound = 1e3 * max(r["bytes"] / B, r["flops"] / F)
            print(f"{scheme:>32} {mesh:>11} {r['vertices']:>9} {r['unknowns']:>9} "
                  f"{r['ms']:>9.1f} {r['iterations']:>7.2f} {bound:>9.1f} "
                  f"{r['ms'] / bound:>6.1f} {r['peak_mb']:>8.0f} {r['estimate_mb']:>8.0f} "
                  f"{r['fixed_mb']:>8.0f} {r['growing_mb']:>8.0f} {r['load']:>5.1f}")
        for problem in dict.fromkeys(m.split(":")[0] for m in args.meshes):
            mine = [best[(scheme, m)] for m in args.meshes
                    if m.startswith(problem + ":") and (scheme, m) in best]
            top = sorted(mine, key=lambda r: r["vertices"])[-3:]
            if len(top) < 2:
                continue
            n = [r["vertices"] for r in top]
            step = power_fit(n, [r["ms"] for r in top])[1]
            it = power_fit(n, [r["ms"] / max(r["iterations"], 1.0) for r in top])[1]
            memory = power_fit(n, [r["growing_mb"] for r in top])[1]
            print(f"{scheme:>32} {problem} slopes on {n} vertices: ms/step n^{step:.2f} "
                  f"(per iteration n^{it:.2f}), growing memory n^{memory:.2f}")
    print("bound = max(bytes / B, flops / F) (bench_bound.py's counting model); ms/step: "
          "median CPU ms of the timed steps after one warm-up step; peak MB: the child's "
          "peak resident memory above its resident memory after the imports; est. MB: "
          "mcfbench.running.cost.estimate of the same; fixed MB: the level-1 run's peak above "
          "the same (kernels, first calls); grows MB: the peak above the resident memory "
          "after the level-1 run (the part that grows with the mesh)")
    print(footing())


if __name__ == "__main__":
    main()
