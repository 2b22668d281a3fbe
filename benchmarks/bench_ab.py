"""One level of a problem (the sphere of Table 3.1): a git revision's tree against the working tree.

Paired A/B for a change whose gain is smaller than the noise of a shared
machine: two persistent child processes pinned to the same core, one
importing the tree at ``--rev`` (``git archive`` into a temporary
directory), one this working tree, each warmed up on levels 1 and 4 of
every scheme (another ``--problem``: on its level 1), then
``_harness.harness_run(scheme, level, problem=problem)``
(:func:`mcfbench.running.run.run` as the command line runs it) in each
alternately, the order reversed every other pair (both trees must end with
the same status; a run that is not ``ok`` is timed to where it stopped).
Prints per scheme the
medians of the wall and CPU seconds, the median of the paired ratios
(working tree / revision), iterations and the metrics (the sphere's: the L2
error (3.2)) of both, and whether every run of both trees ended with the same
status, iterations and metrics to the last bit (a change meant to leave the
results alone).

    python benchmarks/bench_ab.py --rev 951fb48 [--level 5] [--repeats 5]
        [--schemes ddfv cotan] [--problem sphere]

``--problem catenoid --level 3`` (6 000 steps on a small mesh) weighs the
fixed cost of a step: the driver, its checks and observers.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported; the children inherit them

import argparse  # noqa: E402
import json  # noqa: E402
import tempfile  # noqa: E402

from _harness import ROOT, Child, extract, machine_line, median, one_core  # noqa: E402

_CHILD = r'''
import json, os, sys
sys.path[:0] = [os.getcwd(), os.path.join(os.getcwd(), "benchmarks")]
from _harness import harness_run
from mcfbench.storage.memory import tune_malloc
tune_malloc()
import ddfv
problem, schemes = sys.argv[1], sys.argv[2:]
for scheme in schemes:
    harness_run(scheme, 1, problem=problem)
    if problem == "sphere":
        harness_run(scheme, 4)
print(json.dumps({"ready": ddfv.__file__}), flush=True)
for line in sys.stdin:
    scheme, level = line.split()
    r, _ = harness_run(scheme, int(level), problem=problem)
    print(json.dumps({"wall": r.wall_seconds, "cpu": r.cpu_seconds, "status": r.status,
                      "iterations": r.iterations, "metrics": r.metrics}),
          flush=True)
'''


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rev", required=True, help="the tree to compare against (git revision)")
    parser.add_argument("--level", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--schemes", nargs="+", default=["ddfv", "cotan"])
    parser.add_argument("--problem", default="sphere", help="a problem of the registry")
    args = parser.parse_args(argv)
    one_core()
    print(f"bench_ab: {machine_line()}")
    with tempfile.TemporaryDirectory(prefix=f"ab-{args.rev}-") as tree:
        extract(args.rev, tree)
        trees = {"rev": Child(tree, _CHILD, [args.problem, *args.schemes]),
                 "work": Child(ROOT, _CHILD, [args.problem, *args.schemes])}
        runs = {(k, s): [] for k in trees for s in args.schemes}
        try:
            for rep in range(args.repeats):
                for scheme in args.schemes:
                    for k in (("rev", "work") if rep % 2 == 0 else ("work", "rev")):
                        runs[k, scheme].append(trees[k].ask(f"{scheme} {args.level}"))
                    statuses = {r["status"] for k in trees for r in runs[k, scheme]}
                    if len(statuses) > 1:     # a run that is not ok is timed if both agree
                        raise RuntimeError(f"{scheme} {args.problem} level {args.level}: the "
                                           f"two trees end {' and '.join(sorted(statuses))}")
        finally:
            for t in trees.values():
                t.close()
    print(f"{args.problem} level {args.level}, {args.repeats} pairs, interleaved; "
          f"{args.rev} = rev, "
          "the working tree = work; ratios: medians of the paired work / rev")
    for scheme in args.schemes:
        a, b = runs["rev", scheme], runs["work", scheme]
        print(f"{scheme:>8}: rev wall {median(r['wall'] for r in a):.3f} s, CPU "
              f"{median(r['cpu'] for r in a):.3f} s | work wall "
              f"{median(r['wall'] for r in b):.3f} s, CPU {median(r['cpu'] for r in b):.3f} s | "
              f"work / rev wall {median(y['wall'] / x['wall'] for x, y in zip(a, b)):.3f}, CPU "
              f"{median(y['cpu'] / x['cpu'] for x, y in zip(a, b)):.3f} | iterations "
              f"{a[0]['iterations']} / {b[0]['iterations']}, status {a[0]['status']}")
        for name in a[0]["metrics"]:
            print(f"{'':>10}{name} {a[0]['metrics'][name]:.6e} / "
                  f"{b[0]['metrics'].get(name, float('nan')):.6e}")
        same = all(json.dumps([r[k] for k in ("status", "iterations", "metrics")])
                   == json.dumps([a[0][k] for k in ("status", "iterations", "metrics")])
                   for r in a + b)        # JSON floats are the shortest exact repr
        print(f"{'':>10}every run's status, iterations and metrics "
              f"{'bitwise equal' if same else 'DIFFER'} (rev and work)")
    print(f"load average at the end: {machine_line()}")


if __name__ == "__main__":
    main()
