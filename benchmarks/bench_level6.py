"""Speed and memory of a level-6 (or 7) sphere run on the harness, one thread.

The paper's DDFV variant breaks down on level 6 (ddfv/README.md,
results/beyond/), so the scheme timed by default is one that completes,
``ddfv-chord``; any scheme of the registry can be given. Each run is
``mcfbench.running.run.run(scheme, "sphere", level)`` as on the command line
(flow construction, every step, the error (3.2), the T monitor, quality
samples), in a FRESH child process pinned to one core with one BLAS thread
and glibc's malloc tuned, after a warm-up on level 1 in that process (no
JIT compilation or cache loading timed), so that its peak resident memory
(``resource.getrusage(...).ru_maxrss``) is its own.

Levels 4 and 5 are timed too (``--compare-levels``, interleaved over
``--repeats-small`` runs) to show the cost per unknown and step against
the problem size; it should stay about constant (the solver needs about
1.3 BiCGStab iterations a step at every level). Then the verdict against
the targets of the issue (<= 35 s, <= 1 GB) and, for every level above
the finest one run up to 7, an ESTIMATE of its time (cost per unknown and
step of the finest level run x unknowns x steps) and memory (the growth of
the peak above the warmed-up process, scaled with the unknowns).

    python benchmarks/bench_level6.py                      # level 6, ddfv-chord, + 4, 5
    python benchmarks/bench_level6.py --level 7            # 491 522 unknowns, 8192 steps
    python benchmarks/bench_level6.py --scheme cotan --compare-levels
    python benchmarks/bench_level6.py --level 7 --steps 2  # smoke test: 2 steps only
    python benchmarks/bench_level6.py --threads 1          # no two-thread run

``--threads N`` (default 2) also runs the level with N threads (the
``threads`` setting: solver and DDFV's compiled passes), in a fresh child
on N cores with ``NUMBA_NUM_THREADS = N``, alternating with the one-thread
runs; the target is a speed-up >= 1.5.

The machine is shared and noisy: compare ratios, not absolute seconds.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported
# numba's threads: 1, or those of a threaded child (set by the parent)
os.environ["NUMBA_NUM_THREADS"] = os.environ.get("BENCH_THREADS", "1")

import argparse  # noqa: E402
import gc  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402

from _harness import footing, harness_run, machine_line, median, one_core, split  # noqa: E402

PHASES = ("geometry", "assembly", "solve", "other")


def child(scheme, level, steps):
    """One run in this process; prints a JSON line with its measurements."""
    from mcfbench.storage.memory import tune_malloc

    tune_malloc()
    threads = int(os.environ["NUMBA_NUM_THREADS"])
    if threads == 1:
        one_core()
    else:
        os.sched_setaffinity(0, set(range(threads)))
    harness_run(scheme, 1, threads=threads)                 # JIT / cache loading
    gc.collect()
    rss_warm = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    result, flow = harness_run(scheme, level, steps=steps, threads=threads)
    print(json.dumps({
        "scheme": scheme, "level": level, "threads": threads, "nV": result.nV, "N": result.N,
        "steps_done": result.steps_done, "iterations": result.iterations,
        "status": result.status, "message": result.message,
        "l2_error": result.metrics.get("l2_error"), "wall": result.wall_seconds,
        "cpu": result.cpu_seconds, "phases": split(result, flow),
        "warm_rss_mb": rss_warm / 1024,                     # kilobytes on Linux
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))


def run_child(scheme, level, steps, threads=1):
    command = [sys.executable, __file__, "--child", scheme, str(level)]
    if steps is not None:
        command += ["--steps", str(steps)]
    out = subprocess.run(command, capture_output=True, text=True,
                         env={**os.environ, "BENCH_THREADS": str(threads)})
    if out.returncode:
        raise RuntimeError(f"level {level}: the child failed:\n{out.stderr}")
    return json.loads(out.stdout.strip().splitlines()[-1])


def summary(runs):
    """Medians over runs of one level (memory: the largest peak)."""
    first = runs[0]
    wall = median(r["wall"] for r in runs)
    cpu = median(r["cpu"] for r in runs)
    work = first["nV"] * first["steps_done"]
    return {**{k: first[k] for k in ("scheme", "level", "threads", "nV", "N", "steps_done",
                                     "iterations", "status", "message", "l2_error")},
            "runs": len(runs), "wall": wall, "cpu": cpu, "walls": [r["wall"] for r in runs],
            "phases": {k: median(r["phases"][k] for r in runs) for k in PHASES},
            "peak_rss_mb": max(r["peak_rss_mb"] for r in runs),
            "warm_rss_mb": max(r["warm_rss_mb"] for r in runs),
            "ns_per_unknown_step": 1e9 * wall / work, "cpu_ns_per_unknown_step": 1e9 * cpu / work}


def size(scheme, level):
    """``(unknowns, steps)`` of the sphere at ``level`` for ``scheme`` (without running)."""
    from mcfbench.running.problems import get_problem
    from mcfbench.running.schemes import get_scheme

    problem = get_problem("sphere")
    n_f, n_t = 10 * 4 ** level + 2, 20 * 4 ** level            # icosphere
    unknowns = n_f + n_t if get_scheme(scheme).family == "ddfv" else n_f
    return unknowns, problem.time_steps(problem.tau(level))


def main(argv=None):
    from mcfbench.running.schemes import SCHEMES

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=6, help="the level timed (default 6)")
    parser.add_argument("--scheme", default="ddfv-chord", choices=list(SCHEMES),
                        help="default ddfv-chord (the paper's variant breaks down on level 6)")
    parser.add_argument("--compare-levels", type=int, nargs="*", default=[4, 5],
                        help="coarser levels timed for the cost per unknown and step "
                             "(default 4 5; none: --compare-levels)")
    parser.add_argument("--repeats", type=int, default=1, help="runs of --level (median)")
    parser.add_argument("--repeats-small", type=int, default=3,
                        help="runs of each compared level (median), interleaved")
    parser.add_argument("--steps", type=int, help="stop every run after this many steps "
                        "(smoke test; the targets then do not apply)")
    parser.add_argument("--target-seconds", type=float, default=35.0)
    parser.add_argument("--target-gb", type=float, default=1.0)
    parser.add_argument("--threads", type=int, default=2,
                        help="also run --level on this many threads (default 2; 1: not)")
    parser.add_argument("--json", help="also write the measurements to this file")
    parser.add_argument("--child", nargs=2, metavar=("SCHEME", "LEVEL"), help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.child[0], int(args.child[1]), args.steps)
        return 0

    one_core()           # the one-thread children inherit the affinity
    compare = sorted(set(args.compare_levels) - {args.level})
    print(f"bench_level6: {machine_line()}")
    print(f"{args.scheme} on the sphere (Table 3.1 setting: t_f = 0.08, tau = 0.04/4^(k-1)), "
          "one core, one BLAS thread, every run a fresh process warmed up on level 1"
          + (f"; only {args.steps} steps per run (smoke test)" if args.steps else ""))
    small = {lv: [] for lv in compare}
    for _ in range(args.repeats_small if compare else 0):
        for level in compare:
            small[level].append(run_child(args.scheme, level, args.steps))
    results = [summary(small[lv]) for lv in compare]
    finest_runs, threaded_runs = [], []
    for _ in range(args.repeats):                   # one and N threads alternating
        finest_runs.append(run_child(args.scheme, args.level, args.steps))
        if args.threads > 1:
            threaded_runs.append(run_child(args.scheme, args.level, args.steps, args.threads))
    results.append(summary(finest_runs))
    threaded = summary(threaded_runs) if threaded_runs else None

    head = (f"{'level':>5} {'thr':>3} {'unknowns':>8} {'steps':>5} {'iter':>5} {'runs':>4} {'wall s':>8} "
            f"{'cpu s':>8} {'ms/step':>8} {'geom':>6} {'assem':>6} {'solve':>6} {'other':>6} "
            f"{'peak MB':>8} {'+MB':>6} {'ns/(unk*step)':>13} {'cpu ns':>7} {'growth':>6}")
    print(head)
    print("-" * len(head))
    previous = None
    for m in sorted(results, key=lambda m: m["level"]) + ([threaded] if threaded else []):
        growth = (m["ns_per_unknown_step"] / previous["ns_per_unknown_step"]
                  if previous and m["threads"] == 1 else float("nan"))
        cells = " ".join(f"{m['phases'][k] / m['wall']:6.1%}" if m["phases"][k] == m["phases"][k]
                         else f"{'-':>6}" for k in PHASES)
        print(f"{m['level']:5d} {m['threads']:3d} {m['nV']:8d} {m['steps_done']:5d} {m['iterations']:5d} "
              f"{m['runs']:4d} {m['wall']:8.2f} {m['cpu']:8.2f} "
              f"{1e3 * m['wall'] / max(1, m['steps_done']):8.2f} {cells} "
              f"{m['peak_rss_mb']:8.0f} {m['peak_rss_mb'] - m['warm_rss_mb']:6.0f} "
              f"{m['ns_per_unknown_step']:13.1f} {m['cpu_ns_per_unknown_step']:7.1f} "
              f"{growth:6.2f}")
        if m["status"] != "ok":
            print(f"      level {m['level']}: the run broke down: {m['message']}")
        previous = m
    print("(peak MB: ru_maxrss of the child process; +MB: above the process warmed up on "
          "level 1; growth: ns per unknown and step over the previous row)")
    print(footing())

    finest = results[-1]
    print(f"\nload average at the end: {machine_line()}")
    if args.steps is None:
        wall_ok = finest["wall"] <= args.target_seconds
        mem_ok = finest["peak_rss_mb"] <= 1024 * args.target_gb
        print(f"TARGET level {finest['level']} {args.scheme}, one thread, <= "
              f"{args.target_seconds:g} s: wall {finest['wall']:.1f} s, CPU "
              f"{finest['cpu']:.1f} s: {'met' if wall_ok else 'NOT met'} (in CPU time: "
              f"{'met' if finest['cpu'] <= args.target_seconds else 'NOT met'})")
        print(f"TARGET peak memory <= {args.target_gb:g} GB: {finest['peak_rss_mb']:.0f} MB: "
              f"{'met' if mem_ok else 'NOT met'}; L2 error {finest['l2_error']}, "
              f"{finest['iterations']} iterations")
        if threaded:
            speedup = finest["wall"] / threaded["wall"]
            print(f"TARGET {args.threads} threads >= 1.5 x faster than one: wall "
                  f"{threaded['wall']:.1f} s against {finest['wall']:.1f} s, x{speedup:.2f}: "
                  f"{'met' if speedup >= 1.5 else 'NOT met'}; L2 error "
                  f"{threaded['l2_error']}, {threaded['iterations']} iterations, peak "
                  f"{threaded['peak_rss_mb']:.0f} MB")
    if compare:
        first = results[0]
        print(f"level {first['level']} -> {finest['level']}: unknowns x steps "
              f"x{finest['nV'] * finest['steps_done'] / (first['nV'] * first['steps_done']):.0f}, "
              f"wall x{finest['wall'] / first['wall']:.1f}, cost per unknown and step "
              f"x{finest['ns_per_unknown_step'] / first['ns_per_unknown_step']:.2f}")
    for level in range(finest["level"] + 1, 8) if args.steps is None else ():
        unknowns, steps = size(args.scheme, level)
        scale = unknowns * steps
        grown = (finest["peak_rss_mb"] - finest["warm_rss_mb"]) * unknowns / finest["nV"]
        print(f"ESTIMATE level {level} (not run): {unknowns} unknowns, {steps} steps: about "
              f"{finest['ns_per_unknown_step'] * scale / 1e9:.0f} s wall "
              f"({finest['cpu_ns_per_unknown_step'] * scale / 1e9:.0f} s CPU) at level "
              f"{finest['level']}'s cost per unknown and step, peak about "
              f"{finest['warm_rss_mb'] + grown:.0f} MB (the growth above the warm process "
              "scaled with the unknowns); the iteration count per step may grow too")
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"scheme": args.scheme, "levels": results, "threaded": threaded,
                       "targets": {"seconds": args.target_seconds, "gb": args.target_gb}},
                      out, indent=2)
    return 0


if __name__ == "__main__":
    sys.exit(main())
