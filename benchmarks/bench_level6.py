"""Speed and memory of a level-6 DDFV run against the targets of issue #5.

The paper's variant breaks down on level 6 (ddfv/README.md, results/beyond/),
so the run timed is one that completes: ``--variant chord`` (default) or
``eliminate``. Levels 4 and 5 are timed too, to show how the cost grows
with the problem size: per unknown and step it should stay about constant
(the solver needs about 1.3 BiCGStab iterations a step at every level).

Every run is a fresh child process pinned to one core with one BLAS
thread, so that its peak resident memory (``ru_maxrss``) is its own. For
each level the script prints the median wall time over the repeats, its
split into geometry (diamond quantities, covolumes, checks), assembly,
solve and the rest (T monitor, L2 error, set-up), the peak memory, and the
cost in microseconds per unknown and step with its growth from the previous
level; then the verdict against the targets (default 60 s, 2 GB).

    python benchmarks/bench_level6.py                         # levels 4 5 6, chord
    python benchmarks/bench_level6.py --variant eliminate --repeats 3
    python benchmarks/bench_level6.py --levels 6 --json level6.json

The machine is shared and noisy: compare ratios, not absolute seconds.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

PHASES = ("geometry", "assembly", "solve")


def child(level, variant):
    """One run in this process; prints a JSON line with its measurements."""
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})   # one core
    from ddfv import SphereL2Error, icosphere, simulate, variant_options
    from ddfv.sphere import T_FINAL, level_time_step

    V, F = icosphere(level)
    tau = level_time_step(level)
    steps = int(round(T_FINAL / tau))
    error = SphereL2Error()
    rss_before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    start = time.perf_counter()
    traj = simulate(V, F, tau, steps, save_every=0, observer=error, **variant_options(variant))
    wall = time.perf_counter() - start
    print(json.dumps({
        "level": level, "variant": variant, "nV": len(V) + len(F), "steps": steps,
        "iterations": int(traj.iterations.sum()), "status": traj.status,
        "l2_error": error.value if traj.status == "ok" else None,
        "wall": wall, "timings": traj.timings,
        # kilobytes on Linux
        "rss_before_mb": rss_before / 1024,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))


def run_child(level, variant):
    out = subprocess.run([sys.executable, __file__, "--child", str(level), variant],
                         capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def measure(level, variant, repeats):
    """Medians over ``repeats`` fresh runs; memory: the largest peak."""
    runs = [run_child(level, variant) for _ in range(repeats)]
    first = runs[0]
    wall = statistics.median(r["wall"] for r in runs)
    return {"level": level, "variant": variant, "nV": first["nV"], "steps": first["steps"],
            "iterations": first["iterations"], "status": first["status"],
            "l2_error": first["l2_error"], "repeats": repeats, "wall": wall,
            "walls": [r["wall"] for r in runs],
            "phases": {k: statistics.median(r["timings"][k] for r in runs) for k in PHASES},
            "peak_rss_mb": max(r["peak_rss_mb"] for r in runs),
            "rss_before_mb": max(r["rss_before_mb"] for r in runs),
            "us_per_unknown_step": 1e6 * wall / (first["nV"] * first["steps"])}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", default="chord",
                        help="DDFV variant (ddfv.variants.VARIANTS); default chord")
    parser.add_argument("--levels", type=int, nargs="+", default=[4, 5, 6])
    parser.add_argument("--repeats", type=int, default=1,
                        help="runs of the finest level (median); default 1")
    parser.add_argument("--repeats-small", type=int, default=3,
                        help="runs of every coarser level; default 3")
    parser.add_argument("--target-seconds", type=float, default=60.0)
    parser.add_argument("--target-gb", type=float, default=2.0)
    parser.add_argument("--json", help="also write the measurements to this file")
    parser.add_argument("--child", nargs=2, metavar=("LEVEL", "VARIANT"),
                        help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(int(args.child[0]), args.child[1])
        return 0
    levels = sorted(args.levels)
    print(f"DDFV variant {args.variant!r}, one core, one BLAS thread, every run a fresh "
          f"process; t_f = 0.08, tau = 0.04 / 4^(level-1)")
    print(f"{'level':>5} {'nV':>7} {'steps':>5} {'iter':>5} {'runs':>4} {'wall s':>8} "
          f"{'geom':>6} {'assem':>6} {'solve':>6} {'other':>6} {'peak MB':>8} "
          f"{'us/(nV*step)':>12} {'growth':>6}")
    results, previous = [], None
    for level in levels:
        m = measure(level, args.variant, args.repeats if level == levels[-1]
                    else args.repeats_small)
        other = m["wall"] - sum(m["phases"].values())
        growth = m["us_per_unknown_step"] / previous["us_per_unknown_step"] if previous \
            else float("nan")
        print(f"{level:5d} {m['nV']:7d} {m['steps']:5d} {m['iterations']:5d} "
              f"{m['repeats']:4d} {m['wall']:8.2f} "
              + " ".join(f"{m['phases'][k] / m['wall']:6.1%}" for k in PHASES)
              + f" {other / m['wall']:6.1%} {m['peak_rss_mb']:8.0f} "
              f"{m['us_per_unknown_step']:12.3f} {growth:6.2f}")
        if m["status"] != "ok":
            print(f"      level {level}: the run broke down ({m['status']})")
        results.append(m)
        previous = m
    finest = results[-1]
    wall_ok = finest["wall"] <= args.target_seconds
    mem_ok = finest["peak_rss_mb"] <= 1024 * args.target_gb
    print(f"level {finest['level']}: {finest['wall']:.1f} s wall (target <= "
          f"{args.target_seconds:g} s: {'met' if wall_ok else 'NOT met'}), peak memory "
          f"{finest['peak_rss_mb']:.0f} MB (target <= {args.target_gb:g} GB: "
          f"{'met' if mem_ok else 'NOT met'}); L2 error {finest['l2_error']}")
    if len(results) > 1:
        first = results[0]
        size = (finest["nV"] * finest["steps"]) / (first["nV"] * first["steps"])
        print(f"level {first['level']} -> {finest['level']}: unknowns x steps x{size:.0f}, "
              f"wall x{finest['wall'] / first['wall']:.0f}, cost per unknown and step "
              f"x{finest['us_per_unknown_step'] / first['us_per_unknown_step']:.2f}")
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"variant": args.variant, "levels": results,
                       "targets": {"seconds": args.target_seconds, "gb": args.target_gb},
                       "met": {"wall": wall_ok, "memory": mem_ok}}, out, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
