"""The order of a scheme on the real-mesh problems beyond the matrix's levels (issue 30:
is an EOC below 1.5 the pre-asymptotic level 0, or the reference's accuracy?).

    nice python benchmarks/real_mesh_orders.py --meshes bob nut --levels 0 1 2
    nice python benchmarks/real_mesh_orders.py --meshes bob --levels 3 --schemes cotan \\
        --rows out.jsonl                       # more levels later: rows appended
    nice python benchmarks/real_mesh_orders.py --method direct  # the sparse LU instead

Each run is the matrix's (:func:`mcfbench.running.run.run` on ``real_<mesh>``, by
default with the matrix's solver for these problems, BiCGStab at ``rtol = 1e-9``,
``maxiter = 1000``: config ``matrix.solver``, as the real-mesh problems follow the
level rule ``tau_k = tau_0 / 4^k``, not the ``"mesh"`` rule that ``matrix.mesh_solver``
serves; ``--method`` another of :data:`mcfbench.running.solver.METHODS`, e.g.
``direct``, the robust solver), with the problem's observer
(:class:`mcfbench.running.real_mesh_problems.RealMeshShape`) kept to read the area at
every checkpoint. Per scheme and mesh, the table gives:

* the main metric ``area_error`` per level (the largest relative area error over the
  checkpoints against the reference) and its EOC between consecutive levels;
* the reference's relative accuracy (``area_accuracy / area``, the largest over the
  checkpoints, ``mcfbench/data/meshes/references/<mesh>.json``) and the finest level's
  error over the reference's accuracy at the checkpoint of its largest error: near 1
  the reference cannot measure that level's error;
* the reference-free order ``log2(|A_{k-2} - A_{k-1}| / |A_{k-1} - A_k|)`` of the area at
  the final time from the three finest levels run (the scheme's own convergence,
  whatever the reference);
* the CPU seconds of each level;
* when the rows hold a scheme of the reference file (the cotangent scheme, BGN) on a
  level finer than its levels there (e.g. ``--schemes cotan --levels 3``,
  ``--schemes bgn --levels 2`` on a mesh whose BGN reference stops at level 1): each
  level's error and EOC against a finer reference, that scheme's three finest levels
  run, Richardson-extrapolated at every checkpoint as the reference files' own values
  are (``mcfbench.running.two_scheme_references.scheme_estimate``), with its largest
  relative accuracy: is the order the stored reference shows its own?

One JSON row per run goes to ``--rows`` (appended; the table is made from every row
there, so levels run at different times combine).
"""

import argparse
import json
import math
import os
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.real_mesh_problems import RealMeshShape  # noqa: E402
from mcfbench.running.run import run  # noqa: E402
from mcfbench.running.solver import METHODS, Solver  # noqa: E402
from mcfbench.running.two_scheme_references import scheme_estimate  # noqa: E402

REFERENCES = Path(__file__).resolve().parents[1] / "mcfbench/data/meshes/references"
REFERENCE_SCHEMES = ("cotan", "bgn")
"""The schemes of the reference files (``scheme_levels``), each a finer reference when run
beyond its stored levels."""


def measure(scheme, mesh, level, method="bicgstab"):
    """One run's row: status, vertices, steps, CPU seconds, the metrics and the area and
    volume at every checkpoint (``method``: the solver's, rtol 1e-9, 1000 iterations)."""
    problem = get_problem(f"real_{mesh}")
    shape = RealMeshShape(problem)
    result, _ = run(scheme, problem, level, solver=Solver(method=method, rtol=1e-9,
                                                          maxiter=1000), observers=[shape])
    return {"mesh": mesh, "scheme": scheme, "level": level, "method": method,
            "status": result.status,
            "vertices": result.nF, "steps": result.steps_done, "cpu": result.cpu_seconds,
            **result.metrics, **shape.values()}


def finer_reference(by_level, stored_levels):
    """The area at every checkpoint Richardson-extrapolated from one reference scheme's
    three finest levels run (``by_level``: level -> row), and its largest relative
    accuracy; ``None`` unless those reach beyond ``stored_levels`` (that scheme's levels
    in the reference file)."""
    levels = sorted(k for k in by_level if by_level[k]["status"] == "ok")[-3:]
    if len(levels) < 3 or levels[-1] <= max(stored_levels):
        return None
    estimates = [scheme_estimate(values) for values in
                 zip(*(by_level[k]["area"] for k in levels))]
    return [v for v, _, _ in estimates], max(e / abs(v) for v, e, _ in estimates), levels


def table(rows):
    """The lines of the table (see the module docstring) from the rows of :func:`measure`."""
    runs = {}
    for r in rows:
        runs.setdefault((r["mesh"], r["scheme"]), {})[r["level"]] = r
    lines = ["mesh scheme | area_error per level | EOC | reference accuracy (largest, "
             "relative) | finest error / accuracy | order of the final area from the "
             "three finest levels (no reference) | CPU s per level"]
    for (mesh, scheme), by_level in runs.items():
        reference = json.loads((REFERENCES / f"{mesh}.json").read_text())
        accuracy = [a / v for a, v in zip(reference["area_accuracy"], reference["area"])]
        levels = sorted(by_level)
        errors = [by_level[k]["area_error"] for k in levels]
        eocs = [math.log2(abs(a / b)) if a and b else math.nan
                for a, b in zip(errors, errors[1:])]
        finest = by_level[levels[-1]]
        worst = [abs(a / r - 1) for a, r in zip(finest["area"], reference["area"])]
        j = worst.index(max(worst))
        order = math.nan
        if len(levels) >= 3:
            a = [by_level[k]["area"][-1] for k in levels[-3:]]
            order = math.log2(abs(a[0] - a[1]) / abs(a[1] - a[2]))
        lines.append(
            f"{mesh} {scheme} | " + ", ".join(f"L{k} {e:.3e}" for k, e in zip(levels, errors))
            + " | " + ", ".join(f"{levels[i]}-{levels[i + 1]} {e:.2f}" for i, e in enumerate(eocs))
            + f" | {max(accuracy):.1e} | {worst[j] / accuracy[j]:.1f} | {order:.2f} | "
            + ", ".join(f"{by_level[k]['cpu']:.3g}" for k in levels))
        for reference_scheme in REFERENCE_SCHEMES:
            finer = finer_reference(runs.get((mesh, reference_scheme), {}),
                                    reference["scheme_levels"][reference_scheme])
            if finer is None:
                continue
            values, finer_accuracy, finer_levels = finer
            errors = [max(abs(a / r - 1) for a, r in zip(by_level[k]["area"], values))
                      if by_level[k]["status"] == "ok" else math.nan for k in levels]
            lines.append(
                f"    against {reference_scheme} levels {finer_levels} extrapolated (largest "
                f"relative accuracy {finer_accuracy:.1e}): "
                + ", ".join(f"L{k} {e:.3e}" for k, e in zip(levels, errors)) + " | EOC "
                + ", ".join(f"{levels[i]}-{levels[i + 1]} {math.log2(a / b):.2f}"
                            for i, (a, b) in enumerate(zip(errors, errors[1:]))))
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--meshes", nargs="+", default=["bob", "nut", "noisy_sphere",
                                                        "rounded_cube"])
    parser.add_argument("--schemes", nargs="+", default=["ddfv-chord-bgn-carried", "cotan"])
    parser.add_argument("--levels", nargs="+", type=int, default=[0, 1, 2])
    parser.add_argument("--rows", type=Path, default=Path("real_mesh_orders.jsonl"))
    parser.add_argument("--method", choices=METHODS, default="bicgstab",
                        help="the linear solver (default the matrix's for these problems)")
    args = parser.parse_args()
    for mesh in args.meshes:
        for scheme in args.schemes:
            for level in args.levels:
                row = measure(scheme, mesh, level, args.method)
                with args.rows.open("a") as out:
                    out.write(json.dumps(row) + "\n")
                print(f"{mesh} {scheme} level {level}: {row['status']}, "
                      f"{row['cpu']:.3g} s CPU", flush=True)
    print("\n".join(table([json.loads(line) for line in args.rows.read_text().splitlines()])))


if __name__ == "__main__":
    main()
