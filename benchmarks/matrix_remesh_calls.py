"""The remesh calls of the matrix's ``NAME+remesh`` runs (issue #44), which the run
records do not keep.

    nice python benchmarks/matrix_remesh_calls.py --schemes cotan bgn \\
        --problems real_nut:0,1 real_spot:0 [--store results/runs]

Every ``NAME+remesh`` spec of the matrix cut down to ``--schemes`` (their remeshed
variants) on ``--problems`` (``problem:levels``; the solver rules of
``config/config.yaml``'s ``matrix`` section) is run again as the matrix's batch runs
it (:func:`mcfbench.running.batch.run_spec`), the remesher it builds
(:func:`mcfbench.running.remeshing.mesh_hook`) kept to read its ``calls`` (the
rollbacks' remeshes included) and its rollbacks. Printed per run: the status and main
metric of this run and of the run store's record of the same spec (``--store``; the
same numbers say the record is this run), the remesh calls, the rollbacks and the
remeshes' wall seconds against the run's. A run too short to time once is repeated
(:data:`mcfbench.running.run.SHORT_RUN`): its first execution's remesher is read.
"""

import argparse
import json
import os
import sys
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import yaml  # noqa: E402

import mcfbench.running.run as run_module  # noqa: E402
from mcfbench.running.batch import run_spec  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.storage.run_store import record_path  # noqa: E402
from mcfbench.studies.matrix import remeshed_name  # noqa: E402
from mcfbench.studies.matrix.plan import planned_specs, plan  # noqa: E402

CONFIG = Path(__file__).resolve().parents[1] / "config" / "config.yaml"


def remeshed_specs(schemes, problems):
    """``{(problem, scheme, level): spec}`` of the ``NAME+remesh`` runs of the matrix
    cut down to ``schemes`` (remeshed) on ``problems`` (problem -> levels)."""
    section = yaml.safe_load(CONFIG.read_text())["matrix"]
    section["select"] = {"schemes": [remeshed_name(s) for s in schemes], "problems": problems}
    return planned_specs(plan(section))


def counted_run(spec):
    """:func:`~mcfbench.running.batch.run_spec` of ``spec`` and the first remesher its
    run built on the run's own mesh (not the warm-up's tiny one,
    :func:`mcfbench.running.run.warm_up`)."""
    hooks, original = [], run_module.mesh_hook

    def recording(scheme, mesh, **kwargs):
        hook = original(scheme, mesh, **kwargs)
        hooks.append((len(mesh[0]), hook))
        return hook

    run_module.mesh_hook = recording
    try:
        result, *_ = run_spec(spec)
    finally:
        run_module.mesh_hook = original
    return result, next(hook for vertices, hook in hooks if vertices == result.nF)


def stored(spec, root):
    """The run store's record of ``spec`` as a dict, or None."""
    path = Path(record_path(spec, root))
    return json.loads(path.read_text()) if path.is_file() else None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--schemes", nargs="+", required=True)
    parser.add_argument("--problems", nargs="+", required=True, help="problem:levels")
    parser.add_argument("--store", default="results/runs")
    args = parser.parse_args(argv)
    problems = {p: [int(v) for v in levels.split(",")]
                for p, levels in (item.split(":") for item in args.problems)}
    print(f"{'problem':22} {'scheme':32} {'L':>2} {'status':10} {'metric':>11} "
          f"{'stored status':14} {'stored':>11} {'calls':>5} {'rollbacks':>9} "
          f"{'remesh wall s':>13} {'run wall s':>10}", flush=True)
    for (problem, scheme, level), spec in remeshed_specs(args.schemes, problems).items():
        metric = get_problem(problem).main_metric
        result, hook = counted_run(spec)
        record = stored(spec, args.store) or {}
        value, kept = result.metrics.get(metric, float("nan")), record.get(metric)
        print(f"{problem:22} {scheme:32} {level:2d} {result.status:10} {value:11.4e} "
              f"{record.get('status', '-'):14} "
              f"{'-' if kept is None else format(kept, '11.4e'):>11} {hook.calls:5d} "
              f"{hook.rollback.count:9d} {hook.seconds:13.2f} {result.wall_seconds:10.2f}",
              flush=True)


if __name__ == "__main__":
    main()
