"""Time the sphere experiment of Table 3.1 on the harness, every scheme on the same footing.

Per scheme and level, each run is ``mcfbench.running.run.run(scheme, "sphere",
level)`` exactly as the command line does it (flow construction, every
step, the error (3.2), the T monitor and the mesh-quality samples), after
a warm-up on level 1 so that no JIT compilation or cache loading is timed.
The script prints, as medians over ``--repeats``:

* wall and CPU seconds of the whole run, ms per step, ns per unknown and
  step (unknowns: n_F + n_T for DDFV, n_F for the vertex schemes), solver
  iterations;
* the split of the wall time from ``flow.timings``: geometry kernels
  (diamond quantities, covolumes, state checks; DDFV only), assembly,
  solve (sparse products and vector updates: one compiled BiCGStab) and
  the rest (flow construction, T monitor, error (3.2), quality samples,
  driver);
* the ratio to the previous numpy implementation (commit ``6cc720c``,
  ``git archive`` into a temporary directory, its
  ``ddfv.sphere.sphere_run(level)`` in a persistent child process pinned
  to the same core), per repeat, then the median;
* the DDFV / cotangent ratio at each level, in this process and from the
  command line (``python -m mcfbench sphere-table --levels 1 L --scheme X
  --csv ...``: the level-L row of the CSV; level 1 first so that loading
  the compiled kernels is not in it), both in the same run;
* totals over the levels and the verdicts against the targets of the
  issue: level 5 DDFV on one thread <= 2.0 s and <= 0.4 x the old
  implementation, levels 1-5 together <= 2.5 s.

Old and new are interleaved (old, new, ..., the order reversed every other
repeat), one core pinned, one BLAS thread, glibc's malloc tuned. The
machine is shared and noisy: compare the ratios measured in one run, not
absolute seconds across runs. When the level-5 wall target is missed the
script profiles one DDFV run at the finest level (``--no-profile`` skips
it; ``--profile`` forces it): seconds per step of each phase and of the
heaviest functions (cProfile), products per step and time per product.

``--jit``: start-up of a fresh interpreter to the first step done with a
warm numba cache (target <= 1 s) and the cold compilation of every kernel
into an empty ``NUMBA_CACHE_DIR`` (target <= 10 s).

    python benchmarks/bench_sphere.py [--levels 1 2 3 4 5] [--repeats 3]
        [--schemes ddfv cotan] [--no-old] [--no-cli] [--jit] [--profile]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import csv  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from _harness import (  # noqa: E402
    OLD_REV,
    ROOT,
    OldWorker,
    footing,
    harness_run,
    machine_line,
    median,
    one_core,
    split,
)

from mcfbench.storage.memory import tune_malloc  # noqa: E402

TARGET_L5_SECONDS = 2.0
TARGET_L5_RATIO = 0.4
TARGET_TOTAL_SECONDS = 2.5
TARGET_WARM_START = 1.0
TARGET_COLD_COMPILE = 10.0
PHASES = ("geometry", "assembly", "solve", "other")
PARTS = {                      # parts of a run for the profile: (file name, function)
    "flow construction": ("schemes.py", "make"),
    "time steps (geometry, assembly, solve)": ("flow.py", "step"),
    "  of which the solver call": ("solver.py", "solve"),
    "state checks (defects)": ("flow.py", "defects"),
    "error (3.2) observer": ("errors.py", "__call__"),
    "T monitor + quality observer": ("studies.py", "__call__"),
    "  of which quality samples": ("studies.py", "sample"),
    "frames kept by the driver": ("flow.py", "frame"),
}


def verdict(ok):
    return "met" if ok else "NOT met"


# --- one run of each kind -------------------------------------------------------------

def new_run(scheme, level, solver):
    result, flow = harness_run(scheme, level, solver=solver)
    if result.status != "ok":
        raise RuntimeError(f"{scheme} level {level}: {result.message}")
    return {"wall": result.wall_seconds, "cpu": result.cpu_seconds, "nV": result.nV,
            "N": result.N, "iterations": result.iterations,
            "l2_error": result.metrics.get("l2_error"), "phases": split(result, flow)}


def cli_run(scheme, level, solver, tmp):
    """``python -m mcfbench sphere-table --levels 1 level --scheme scheme``: the level row."""
    out = Path(tmp) / f"{scheme}.csv"
    levels = ["1", str(level)] if level > 1 else ["1"]
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "mcfbench", "sphere-table", "--levels", *levels,
                    "--scheme", scheme, "--solver", solver.method, "--rtol", repr(solver.rtol),
                    "--csv", str(out)], cwd=ROOT, check=True, capture_output=True, text=True)
    process = time.perf_counter() - start
    with open(out) as handle:
        row = [r for r in csv.DictReader(handle) if int(r["level"]) == level][0]
    return {"wall": float(row["wall_seconds"]), "cpu": float(row["cpu_seconds"]),
            "process": process, "iterations": int(row["iterations"])}


# --- the tables -----------------------------------------------------------------------

def print_scheme_table(scheme, levels, runs, old, solver):
    """One scheme: medians per level, split, ratio to the old implementation."""
    print(f"\n{scheme}: medians of {len(runs[levels[0]])} runs (whole run: construction, "
          "steps, error (3.2), T monitor, quality)")
    head = (f"{'level':>5} {'unknowns':>8} {'steps':>5} {'iter':>5} {'wall s':>8} {'cpu s':>8} "
            f"{'ms/step':>8} {'ns/(unk*step)':>13} {'geom':>6} {'assem':>6} {'solve':>6} "
            f"{'other':>6}")
    if old:
        head += f" {'old s':>8} {'new/old':>7}"
    print(head)
    print("-" * len(head))
    totals = {"wall": 0.0, "cpu": 0.0, "old": 0.0}
    for level in levels:
        rs = runs[level]
        wall, cpu = median(r["wall"] for r in rs), median(r["cpu"] for r in rs)
        first = rs[0]
        phases = {k: median(r["phases"][k] for r in rs) for k in PHASES}
        cells = " ".join(f"{phases[k] / wall:6.1%}" if phases[k] == phases[k] else f"{'-':>6}"
                         for k in PHASES)
        line = (f"{level:5d} {first['nV']:8d} {first['N']:5d} {first['iterations']:5d} "
                f"{wall:8.3f} {cpu:8.3f} {1e3 * wall / first['N']:8.3f} "
                f"{1e9 * wall / (first['N'] * first['nV']):13.1f} {cells}")
        totals["wall"] += wall
        totals["cpu"] += cpu
        if old:
            old_wall = median(o["wall"] for o in old[level])
            ratio = median(r["wall"] / o["wall"] for r, o in zip(rs, old[level]))
            line += f" {old_wall:8.3f} {ratio:7.3f}"
            totals["old"] += old_wall
        print(line)
    line = (f"total levels {levels[0]}-{levels[-1]}: wall {totals['wall']:.3f} s, "
            f"CPU {totals['cpu']:.3f} s")
    if old:
        line += (f"; old implementation {totals['old']:.3f} s wall, "
                 f"new/old {totals['wall'] / totals['old']:.3f}")
    print(line)
    print("(geom/assem/solve/other: shares of the wall time, from flow.timings; solve = "
          "products + vector updates of the compiled BiCGStab; other = construction, "
          "monitors, error, driver)")
    print(footing(solver.method, solver.rtol))
    return totals


def print_ratio_table(levels, runs, cli, solver):
    """DDFV / cotangent per level: in this process, and from the command line."""
    print("\nDDFV / cotangent time ratio per level (paired per repeat, median)")
    head = f"{'level':>5} {'wall':>7} {'cpu':>7} {'per unknown+step':>16}"
    print(head)
    print("-" * len(head))
    for level in levels:
        d, c = runs["ddfv"][level], runs["cotan"][level]
        wall = median(a["wall"] / b["wall"] for a, b in zip(d, c))
        cpu = median(a["cpu"] / b["cpu"] for a, b in zip(d, c))
        unknowns = d[0]["nV"] / c[0]["nV"]
        print(f"{level:5d} {wall:7.2f} {cpu:7.2f} {wall / unknowns:16.2f}")
    if cli:
        d, c = cli["ddfv"], cli["cotan"]
        level = cli["level"]
        print(f"command line (python -m mcfbench sphere-table --levels 1 {level} --scheme X), "
              f"level {level}, {len(d)} runs each, interleaved:")
        for name, rs in (("ddfv", d), ("cotan", c)):
            print(f"  {name:6s} wall {median(r['wall'] for r in rs):7.3f} s, CPU "
                  f"{median(r['cpu'] for r in rs):7.3f} s, whole process "
                  f"{median(r['process'] for r in rs):7.3f} s, {rs[0]['iterations']} iterations")
        print(f"  DDFV / cotangent: wall {median(a['wall'] / b['wall'] for a, b in zip(d, c)):.2f}"
              f", CPU {median(a['cpu'] / b['cpu'] for a, b in zip(d, c)):.2f}, whole process "
              f"{median(a['process'] / b['process'] for a, b in zip(d, c)):.2f}")
    print(footing(solver.method, solver.rtol))


# --- profile of the finest level ------------------------------------------------------

class _Recording:
    """The solver, keeping the last system it was given (for the product timing)."""

    def __init__(self, solver):
        self.solver, self.method, self.rtol = solver, solver.method, solver.rtol
        self.last, self.calls = None, 0

    def __call__(self, A, b, x0):
        self.last = (A, b, x0)
        self.calls += 1
        return self.solver(A, b, x0)


def profile(level, solver, runs, repeats=30):
    """Where the time of one DDFV run at ``level`` goes."""
    import cProfile
    import pstats

    import numpy as np

    from mcfbench.running.solver import apply_block

    rs = runs["ddfv"][level]
    N, nV, iterations = rs[0]["N"], rs[0]["nV"], rs[0]["iterations"]
    wall = median(r["wall"] for r in rs)
    print(f"\nProfile of DDFV at level {level} ({nV} unknowns, {N} steps, {iterations} "
          f"iterations = {iterations / N:.2f} per step)")
    print("phases (flow.timings, medians of the runs above), ms per step:")
    for k in PHASES:
        value = median(r["phases"][k] for r in rs)
        print(f"  {k:9s} {1e3 * value / N:8.3f} ms/step  {value / wall:6.1%}")
    # products: BiCGStab does 2 per iteration and 1 for the initial residual
    recorder = _Recording(solver)
    profiler = cProfile.Profile()
    profiler.enable()
    result, flow = harness_run("ddfv", level, solver=recorder)
    profiler.disable()
    A, b, x0 = recorder.last
    products = (2 * result.iterations + recorder.calls) / N
    times = []
    Y = np.empty_like(b)
    for _ in range(repeats):
        start = time.perf_counter()
        apply_block(A, b, Y)
        times.append(time.perf_counter() - start)
    product = min(times)
    solve = median(r["phases"]["solve"] for r in rs) / N
    nbytes = A.nnz * (8 + 4) + (A.shape[0] + 1) * 4 + 2 * b.size * 8
    print(f"solve: {products:.2f} block products per step (2 per iteration + 1 initial "
          f"residual) x {1e3 * product:.3f} ms (min of {repeats}; nnz {A.nnz}, "
          f"{nbytes / product / 1e9:.2f} GB/s streamed) = {1e3 * products * product:.3f} "
          f"ms/step of {1e3 * solve:.3f} ms/step; vector updates, dots and call overhead "
          f"{1e3 * (solve - products * product):.3f} ms/step")
    stats = pstats.Stats(profiler).stats
    kernels = _kernel_codes()
    rows = sorted(stats.items(), key=lambda kv: -kv[1][2])
    inside = [(key, v) for key, v in rows if (Path(key[0]).name, key[1], key[2]) in kernels]
    outside = [(key, v) for key, v in rows if (Path(key[0]).name, key[1], key[2]) not in kernels]
    profiled = result.wall_seconds
    print(f"cProfile of one more run (wall {profiled:.3f} s under the profiler; "
          "ms per step, share of that wall time):")
    print("  compiled kernels (own time):")
    total = 0.0
    for (path, line, name), (_, calls, own, _, _) in inside:
        total += own
        print(f"    {1e3 * own / N:8.3f} ms  {own / profiled:6.1%}  {calls / N:5.2f} calls/step  "
              f"{name} ({Path(path).parent.name}/{Path(path).name})")
    print(f"    {1e3 * total / N:8.3f} ms  {total / profiled:6.1%}  all compiled kernels")
    print(f"  the rest ({1e3 * (profiled - total) / N:.3f} ms/step, "
          f"{(profiled - total) / profiled:.1%}), heaviest Python functions by own time "
          "(cumulative in brackets):")
    for (path, line, name), (_, calls, own, cumul, _) in outside[:10]:
        where = f"{Path(path).parent.name}/{Path(path).name}:{line}" if line else "builtin"
        print(f"    {1e3 * own / N:8.3f} ms ({1e3 * cumul / N:7.3f})  {calls / N:6.2f} "
              f"calls/step  {name} ({where})")
    print("  by part, cumulative (kernels called inside included; the lazy geometry of a "
          "new state is computed by whichever part asks first, usually defects):")
    for label, (file, function) in PARTS.items():
        cumul = sum(v[3] for key, v in stats.items()
                    if Path(key[0]).name == file and key[2] == function)
        print(f"    {1e3 * cumul / N:8.3f} ms  {cumul / profiled:6.1%}  {label} "
              f"({file}:{function})")
    return product, products


def _kernel_codes():
    """``(file name, first line, name)`` of every compiled kernel, as cProfile keys them."""
    from numba.core.registry import CPUDispatcher

    import baselines.kernels
    import ddfv.kernels
    from mcfbench.running import solver as solver_module

    codes = set()
    for module in (ddfv.kernels, baselines.kernels, solver_module):
        for value in vars(module).values():
            if isinstance(value, CPUDispatcher):
                code = value.py_func.__code__
                codes.add((Path(code.co_filename).name, code.co_firstlineno, code.co_name))
    return codes


# --- JIT: warm start-up and cold compilation ------------------------------------------

_STARTUP = r'''
import time
t0 = time.perf_counter()
import json, sys
import mcfbench.running.run
from mcfbench.storage.memory import tune_malloc
tune_malloc()
t1 = time.perf_counter()
scheme, level = sys.argv[1], int(sys.argv[2])
tau = mcfbench.running.run.get_problem("sphere").tau(level)
r, _ = mcfbench.running.run.run(scheme, "sphere", level, t_final=tau)     # one step
t2 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "first_step": t2 - t0, "status": r.status}))
'''

_COMPILE = r'''
import time
t0 = time.perf_counter()
import json
from numba.core.registry import CPUDispatcher
import mcfbench.running.run
from mcfbench.running import solver as S
from mcfbench.pipeline import warm_kernels
import ddfv.kernels, baselines.kernels
t1 = time.perf_counter()
warm_kernels()                  # one step of every scheme, every solver method
t2 = time.perf_counter()
kernels = {f"{m.__name__}.{k}": len(v.signatures)      # inlined helpers are not kernels
           for m in (ddfv.kernels, baselines.kernels, S)
           for k, v in vars(m).items()
           if isinstance(v, CPUDispatcher) and v.targetoptions.get("inline") != "always"}
print(json.dumps({"import": t1 - t0, "work": t2 - t1, "kernels": kernels}))
'''

_COMPILE_THREADED = r'''
import time
t0 = time.perf_counter()
import json
from mcfbench.pipeline import warm_kernels
t1 = time.perf_counter()
warm_kernels(2)                 # the threaded copies (the one-thread kernels are cached)
t2 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "work": t2 - t1}))
'''


def _child(code, args, env=None):
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code, *map(str, args)], cwd=ROOT,
                         env={**os.environ, **(env or {})}, capture_output=True, text=True)
    process = time.perf_counter() - start
    if out.returncode:
        raise RuntimeError(out.stderr)
    return {**json.loads(out.stdout.strip().splitlines()[-1]), "process": process}


def jit_section(schemes, levels, repeats):
    print("\nStart-up with a warm numba cache: fresh interpreter, `import mcfbench.running.run`, "
          "then mcfbench.running.run.run(scheme, 'sphere', level) for one step "
          f"(min / median of {repeats}, interleaved)")
    head = f"{'scheme':>8} {'level':>5} {'import s':>8} {'1st step s':>10} {'process s':>9}"
    print(head)
    print("-" * len(head))
    for scheme in schemes:
        _child(_STARTUP, [scheme, 1])                       # make sure the cache is warm
    worst = 0.0
    runs = {(s, lv): [] for s in schemes for lv in levels}
    for _ in range(repeats):
        for key in runs:
            runs[key].append(_child(_STARTUP, key))
    for (scheme, level), rs in runs.items():
        first = min(r["first_step"] for r in rs)
        process = min(r["process"] for r in rs)
        worst = max(worst, process)
        print(f"{scheme:>8} {level:5d} {min(r['import'] for r in rs):8.3f} {first:10.3f} "
              f"{process:9.3f}   (medians {median(r['first_step'] for r in rs):.3f} / "
              f"{median(r['process'] for r in rs):.3f})")
    print(f"target: start-up to the first step done <= {TARGET_WARM_START:g} s (whole "
          f"process, min): worst {worst:.3f} s: {verdict(worst <= TARGET_WARM_START)}")
    with tempfile.TemporaryDirectory(prefix="numba-cold-") as cache:
        cold = _child(_COMPILE, [], {"NUMBA_CACHE_DIR": cache})
        warm = _child(_COMPILE, [], {"NUMBA_CACHE_DIR": cache})
        threaded = {"NUMBA_CACHE_DIR": cache, "NUMBA_NUM_THREADS": "2"}
        cold_threaded = _child(_COMPILE_THREADED, [], threaded)
        warm_threaded = _child(_COMPILE_THREADED, [], threaded)
    compiled = sum(1 for v in cold["kernels"].values() if v)
    signatures = sum(cold["kernels"].values())
    compile_time = cold["work"] - warm["work"]
    print(f"Cold compilation (empty NUMBA_CACHE_DIR): one level-1 step of every scheme and "
          f"every solver method: {cold['work']:.2f} s, the same with that cache warm "
          f"{warm['work']:.2f} s -> compiling {compile_time:.2f} s ({compiled} of "
          f"{len(cold['kernels'])} kernels, {signatures} signatures; whole processes "
          f"{cold['process']:.2f} s cold, {warm['process']:.2f} s warm)")
    missing = [k for k, v in cold["kernels"].items() if not v]
    if missing:
        print(f"  not compiled by that work: {', '.join(missing)}")
    print(f"target: cold compilation of all kernels <= {TARGET_COLD_COMPILE:g} s: "
          f"{compile_time:.2f} s (cold work - warm work): "
          f"{verdict(compile_time <= TARGET_COLD_COMPILE)}")
    print(f"Threaded copies (threads=2; compiled on first use only, the one-thread kernels "
          f"already cached): the same work on 2 threads {cold_threaded['work']:.2f} s "
          f"cold, {warm_threaded['work']:.2f} s warm -> compiling "
          f"{cold_threaded['work'] - warm_threaded['work']:.2f} s (no target)")


# --- main -----------------------------------------------------------------------------

def main(argv=None):
    from mcfbench.running.schemes import SCHEMES
    from mcfbench.running.solver import METHODS, Solver

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--schemes", nargs="+", default=["ddfv", "cotan"],
                        choices=list(SCHEMES), metavar="SCHEME",
                        help=f"default: ddfv cotan; any of {', '.join(SCHEMES)}")
    parser.add_argument("--solver", choices=METHODS, default="bicgstab")
    parser.add_argument("--rtol", type=float, default=1e-9)
    parser.add_argument("--rev", default=OLD_REV, help="the old implementation (git revision)")
    parser.add_argument("--no-old", action="store_true", help="skip the old implementation")
    parser.add_argument("--no-cli", action="store_true", help="skip the command-line runs")
    parser.add_argument("--jit", action="store_true",
                        help="also time the warm start-up and the cold compilation")
    parser.add_argument("--jit-levels", type=int, nargs="+", default=[1, 5])
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--profile", action="store_true", help="always profile the finest level")
    group.add_argument("--no-profile", action="store_true", help="never profile")
    args = parser.parse_args(argv)

    tune_malloc()
    one_core()
    levels = sorted(set(args.levels))
    solver = Solver(args.solver, args.rtol)
    schemes = list(dict.fromkeys(args.schemes))
    print(f"bench_sphere: {machine_line()}")
    print(f"sphere (Table 3.1): icosphere level k, tau = 0.04/4^(k-1), t_final = 0.08; "
          f"solver {solver.method}, rtol {solver.rtol:g}; one BLAS thread")

    if args.jit:
        jit_section(schemes, args.jit_levels, args.repeats)

    for scheme in schemes:                                   # JIT and cache loading
        new_run(scheme, 1, solver)
    runs = {s: {lv: [] for lv in levels} for s in schemes}
    with_old = not args.no_old and "ddfv" in schemes        # the old code is DDFV only
    old = {lv: [] for lv in levels} if with_old else None
    worker = OldWorker(args.rev) if with_old else None
    try:
        for rep in range(args.repeats):
            for level in levels:
                order = ["old", *schemes] if rep % 2 == 0 else [*schemes, "old"]
                for who in order:
                    if who == "old":
                        if worker is not None:
                            old[level].append(worker.run(level))
                    else:
                        runs[who][level].append(new_run(who, level, solver))
    finally:
        if worker is not None:
            worker.close()

    totals = {}
    for scheme in schemes:
        totals[scheme] = print_scheme_table(scheme, levels, runs[scheme],
                                            old if scheme == "ddfv" else None, solver)
    if old:
        print(f"(old = ddfv.sphere.sphere_run of {args.rev}, the numpy implementation, "
              "in a child process on the same core, interleaved with the new runs; "
              "new/old = median over repeats of the paired ratios)")

    cli = None
    if "ddfv" in schemes and "cotan" in schemes:
        if not args.no_cli:
            top = levels[-1]
            cli = {"level": top, "ddfv": [], "cotan": []}
            with tempfile.TemporaryDirectory(prefix="bench-cli-") as tmp:
                for rep in range(args.repeats):
                    for scheme in (("ddfv", "cotan") if rep % 2 == 0 else ("cotan", "ddfv")):
                        cli[scheme].append(cli_run(scheme, top, solver, tmp))
        print_ratio_table(levels, runs, cli, solver)

    print(f"\nload average at the end: {machine_line()}")
    missed = False
    if "ddfv" in schemes and 5 in levels:
        rs = runs["ddfv"][5]
        wall, cpu = median(r["wall"] for r in rs), median(r["cpu"] for r in rs)
        best = min(r["wall"] for r in rs)
        missed = wall > TARGET_L5_SECONDS
        print(f"TARGET level 5 DDFV, one thread, <= {TARGET_L5_SECONDS:g} s: wall {wall:.3f} s "
              f"median (min {best:.3f}), CPU {cpu:.3f} s: {verdict(not missed)} "
              f"(in CPU time: {verdict(cpu <= TARGET_L5_SECONDS)})")
        if old:
            ratio = median(r["wall"] / o["wall"] for r, o in zip(rs, old[5]))
            cpu_ratio = median(r["cpu"] / o["cpu"] for r, o in zip(rs, old[5]))
            print(f"TARGET level 5 DDFV <= {TARGET_L5_RATIO:g} x the old implementation: "
                  f"new/old {ratio:.3f} (wall), {cpu_ratio:.3f} (CPU): "
                  f"{verdict(ratio <= TARGET_L5_RATIO)}")
        if all(lv in levels for lv in range(1, 6)):
            total = sum(median(r["wall"] for r in runs["ddfv"][lv]) for lv in range(1, 6))
            total_cpu = sum(median(r["cpu"] for r in runs["ddfv"][lv]) for lv in range(1, 6))
            print(f"TARGET levels 1-5 DDFV together <= {TARGET_TOTAL_SECONDS:g} s: wall "
                  f"{total:.3f} s, CPU {total_cpu:.3f} s: {verdict(total <= TARGET_TOTAL_SECONDS)}"
                  f" (in CPU time: {verdict(total_cpu <= TARGET_TOTAL_SECONDS)})")
        print(footing(solver.method, solver.rtol))
    if "ddfv" in schemes and (args.profile or (missed and not args.no_profile)):
        profile(levels[-1], solver, runs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
