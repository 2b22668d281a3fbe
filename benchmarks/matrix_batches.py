"""The matrix's time outside its runs and the batching of its Snakemake jobs, from a
finished matrix's records and benchmark files (issue 32).

Three parts, each printed:

1. *Outside the runs*: per batch job of the matrix as it ran
   (:func:`~mcfbench.running.batching.batches` of the matrix's specs alone, as this
   code packs them; for a matrix of older code, ``--ran-budget``:
   :func:`~mcfbench.running.batching.pack` of the cost model's estimates
   without :data:`~mcfbench.running.batching.MATRIX_FACTORS`, as before
   them, by that budget: 10 s up to f699a17), its wall seconds (Snakemake's
   ``benchmark:`` file; its ``cpu_time`` is sampled and stops growing between
   samples, so the wall time is used) less its runs' wall seconds (each
   record's ``wall_seconds`` times its ``timing_repeats``, and its robust
   re-run's); the sum, the median, and a least-squares fit
   ``a + b series + c runs`` (:data:`~mcfbench.running.batching.BATCH_SECONDS`).
2. *The cost model against the records*: per kind of scheme
   (:func:`mcfbench.running.cost.cost_class`), the median over the series
   (above 0.3 s) of the measured CPU seconds over the model's
   (:data:`~mcfbench.running.batching.MATRIX_FACTORS`).
3. *Batches replayed*: for each budget, the jobs that
   :func:`~mcfbench.running.batching.pack` makes of the current estimates
   (:func:`~mcfbench.running.batching.spec_seconds` of a series' runs), each lasting its
   records' CPU seconds and the fitted cost of part 1, started costliest
   estimate first on 2 cores (as Snakemake's priorities do): the job count, the
   time both cores are done and their difference.

Usage (``CLONE``: a checkout where ``snakemake --cores 2 matrix`` finished, its
``results/`` in place; ``--ran-budget``: the budget of code before the factors)::

    python benchmarks/matrix_batches.py CLONE [--ran-budget 10] \\
        [--budgets 10 30 60 90]
"""

import argparse
import csv
import json
import statistics
from collections import defaultdict
from pathlib import Path


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("checkout", type=Path, help="the checkout the matrix ran in")
    parser.add_argument("--ran-budget", type=float, default=None,
                        help="BATCH_SECONDS of the code that ran the matrix, when that "
                        "code packed its batches without MATRIX_FACTORS (default: the "
                        "batches of this code, plan.batches)")
    parser.add_argument("--budgets", type=float, nargs="+", default=[10, 30, 60, 90])
    args = parser.parse_args()
    import numpy as np
    import yaml

    from mcfbench.running.cost import cost_class, estimate, size
    from mcfbench.running.problems import get_problem
    from mcfbench.running.schemes import get_scheme
    from mcfbench.running import batching
    from mcfbench.storage.run_store import record_path
    from mcfbench.studies.matrix import plan as matrix_plan

    root = args.checkout / "results"
    config = yaml.safe_load((args.checkout / "config/config.yaml").read_text())
    plan = matrix_plan.plan(config["matrix"])

    specs = matrix_plan.planned_specs(plan)

    def record(problem, scheme, level):
        """The run store's record, or one of the matrix's own folder (before the store)."""
        path = Path(record_path(specs[problem, scheme, level], root=root / "runs"))
        if not path.is_file():
            path = root / "matrix" / "runs" / problem / scheme / f"level{level}.json"
        return json.loads(path.read_text())

    series = {}          # (problem, scheme) -> (model s, measured CPU s, runs wall s, runs)
    for problem, levels in plan["problems"].items():
        for scheme in plan["schemes"]:
            entry, runs = get_scheme(scheme), [record(problem, scheme, k) for k in levels]
            model = sum(estimate(entry, *size(entry, get_problem(problem), k)).seconds
                        for k in levels)
            cpu = sum(r["cpu_seconds"] + (r.get("robust_cpu_seconds") or 0.0) for r in runs)
            wall = sum(r["wall_seconds"] * r.get("timing_repeats", 1)
                       + (r.get("robust_wall_seconds") or r.get("robust_cpu_seconds") or 0.0)
                       for r in runs)
            series[problem, scheme] = (model, cpu, wall, len(levels))

    # 1. outside the runs, per batch job of the matrix as it ran
    if args.ran_budget is None:
        ran = [(b.problem, f"runs/{b.name}", list(dict.fromkeys(s.scheme for s in b.specs)))
               for b in batching.batches({"matrix": list(specs.values())})]
    else:
        ran = []
        for problem, levels in plan["problems"].items():
            old = {s: series[problem, s][0] + batching.RUN_SECONDS * len(levels)
                   for s in plan["schemes"]}
            ran += [(problem, f"matrix/{problem}/batch{index}", group) for index, group
                    in enumerate(batching.pack(old, args.ran_budget), start=1)]
    rows = []
    for problem, name, group in ran:
        tsv = root / "benchmarks" / f"{name}.tsv"
        with open(tsv) as handle:
            job_wall = float(next(csv.DictReader(handle, delimiter="\t"))["s"])
        parts = [series[problem, s] for s in group]
        rows.append((job_wall - sum(p[2] for p in parts), len(parts),
                     sum(p[3] for p in parts)))
    outside = np.array([r[0] for r in rows])
    fit = np.linalg.lstsq(np.array([[1.0, r[1], r[2]] for r in rows]), outside, rcond=None)[0]
    print(f"1. {len(rows)} batch jobs, {sum(r[2] for r in rows)} runs: outside the runs "
          f"{outside.sum():.0f} s (wall), median {np.median(outside):.2f} s a job; fit "
          f"{fit[0]:.2f} s + {fit[1]:.3f} s a series + {fit[2]:.3f} s a run")

    # 2. the cost model against the records, per kind of scheme
    ratios = defaultdict(list)
    for (problem, scheme), (model, cpu, _, _) in series.items():
        if cpu > 0.3 and model > 0:
            ratios[cost_class(get_scheme(scheme))].append(cpu / model)
    print("2. measured / model CPU seconds of a series (median; MATRIX_FACTORS beside):")
    for kind, values in ratios.items():
        print(f"   {kind:24s} {len(values):4d} series {statistics.median(values):6.2f} "
              f"({batching.MATRIX_FACTORS.get(kind, 1.0)})")

    # 3. the batches replayed with the current estimates
    estimates = {(p, s): sum(batching.spec_seconds(specs[p, s, k])
                             for k in plan["problems"][p]) for p, s in series}
    print("3. budget   jobs   runs end   cores apart")
    for budget in args.budgets:
        jobs = []
        for problem in plan["problems"]:
            costs = {s: estimates[problem, s] for s in plan["schemes"]}
            for group in batching.pack(costs, budget):
                parts = [series[problem, s] for s in group]
                length = sum(p[1] for p in parts) + fit @ [1.0, len(parts),
                                                           sum(p[3] for p in parts)]
                jobs.append((-round(sum(costs[s] for s in group)), len(jobs), length))
        cores = [0.0, 0.0]
        for _, _, length in sorted(jobs):
            cores[int(np.argmin(cores))] += length
        print(f"   {budget:6.0f} {len(jobs):6d} {max(cores):9.0f} s {abs(cores[0] - cores[1]):7.1f} s")


if __name__ == "__main__":
    main()
