"""Run one experiment of ddfv.experiments and draw its figure.

Called by rule ``figure`` (workflow/rules/figures.smk) through Snakemake's
``script:`` directive, or by hand:

    python workflow/scripts/figure.py fig_3_2     # default paths under results/
    python workflow/scripts/figure.py fig_3_2 \
        --png results/figures/fig_3_2.png --pdf results/figures/fig_3_2.pdf \
        --frames results/runs/figures/fig_3_2.npz --record results/runs/figures/fig_3_2.json \
        --csv results/diagnostics/fig_3_2.csv --plot results/diagnostics/fig_3_2.png

Writes the figure (PNG + PDF), the kept frames of every run (npz, keys
``<run>.F``, ``<run>.T``, ``<run>.steps``, ``<run>.faces``, ``<run>.iterations``),
the per-step diagnostics of the DDFV runs (CSV with a ``run`` column, and
a plot) and a JSON record (status per run, first violation, timings,
provenance). A run that breaks down keeps its frames and the figure is
drawn from them with a note; the exit status is 0 unless the script itself
fails. ``--list`` prints the experiment names.
"""

import argparse
import json
import os
import sys
import time
from pathlib import Path

# one BLAS thread per job (rule figure declares threads: 1); set before numpy loads
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # the repository

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from ddfv.diagnostics import COLUMNS, plot_quality  # noqa: E402
from ddfv.experiments import (EXPERIMENTS, draw_experiment, experiment_status,  # noqa: E402
                              run_experiment)
from ddfv.provenance import provenance  # noqa: E402
from ddfv.render import save_figure  # noqa: E402


def main(argv=None):
    """Command line; see the module docstring."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("name", nargs="?", help="experiment (figure) name, e.g. fig_3_2")
    parser.add_argument("--list", action="store_true", help="list the experiments")
    for option in ("png", "pdf", "frames", "record", "csv", "plot"):
        parser.add_argument(f"--{option}", type=Path)
    args = parser.parse_args(argv)
    if args.list or args.name is None:
        print("\n".join(EXPERIMENTS))
        return 0
    if args.name not in EXPERIMENTS:
        parser.error(f"unknown experiment {args.name!r}; choose one of {', '.join(EXPERIMENTS)}")
    out = {k: getattr(args, k) or default for k, default in defaults(args.name).items()}
    return make_figure(args.name, out)


def make_figure(name, out):
    """Run experiment ``name`` and write the files ``out`` (keys as :func:`defaults`)."""
    experiment = EXPERIMENTS[name]
    out = {k: Path(v) for k, v in out.items()}
    wall = time.perf_counter()
    results = run_experiment(experiment)
    compute = time.perf_counter() - wall
    for path in out.values():
        path.parent.mkdir(parents=True, exist_ok=True)

    arrays = {}
    for key, r in results.items():
        arrays.update({f"{key}.F": r.F, f"{key}.steps": r.steps, f"{key}.faces": r.faces,
                       f"{key}.iterations": r.iterations})
        if r.T is not None:
            arrays[f"{key}.T"] = r.T
    np.savez_compressed(out["frames"], **arrays)

    tables = {r.run.label or key: r.quality for key, r in results.items()
              if r.quality is not None}
    frames = [df.assign(run=key) for key, df in
              ((k, r.quality) for k, r in results.items() if r.quality is not None)]
    table = pd.concat(frames, ignore_index=True) if frames else \
        pd.DataFrame(columns=["run", *COLUMNS])
    table = table[["run", *COLUMNS]]
    table.to_csv(out["csv"], index=False)
    marks = sorted({s.step for s in experiment.shots})
    save_figure(plot_quality(tables, title=f"{experiment.name}: {experiment.title}",
                             marks=marks), out["plot"])

    draw = time.perf_counter()
    save_figure(draw_experiment(experiment, results), out["png"], out["pdf"])
    draw = time.perf_counter() - draw

    status = experiment_status(results)
    record = {
        "experiment": experiment.name,
        "title": experiment.title,
        "status": status,
        "first_violation": {key: r.record()["first_violation"] for key, r in results.items()
                            if r.quality is not None},
        "runs": {key: r.record() for key, r in results.items()},
        "seconds": {"compute": round(compute, 3), "draw": round(draw, 3),
                    "total": round(time.perf_counter() - wall, 3)},
        "outputs": {k: str(v) for k, v in out.items()},
        "provenance": provenance(experiment.config()),
    }
    out["record"].write_text(json.dumps(record, indent=2) + "\n")
    for key, r in results.items():
        line = f"{experiment.name}/{key}: {r.status}, n = {int(r.steps[-1])}"
        if r.message:
            line += f" ({r.message})"
        violation = r.record()["violation"]
        if violation:
            line += f"; first violation at {violation}"
        print(line, file=sys.stderr if r.status != "ok" else sys.stdout)
    print(f"{experiment.name}: {status}; compute {compute:.1f} s, draw {draw:.1f} s")
    return 0


def defaults(name, results="results"):
    """Default output paths of an experiment (the ones of workflow/rules/figures.smk)."""
    root = Path(results)
    return {
        "png": root / "figures" / f"{name}.png",
        "pdf": root / "figures" / f"{name}.pdf",
        "frames": root / "runs" / "figures" / f"{name}.npz",
        "record": root / "runs" / "figures" / f"{name}.json",
        "csv": root / "diagnostics" / f"{name}.csv",
        "plot": root / "diagnostics" / f"{name}.png",
    }


def _from_snakemake(smk):
    """Entry point under Snakemake's ``script:``: outputs by name, stdout/err to the log."""
    with open(smk.log[0], "w") as log:
        sys.stdout = sys.stderr = log
        make_figure(smk.wildcards.figure, {k: smk.output[k] for k in defaults("")})


if __name__ == "__main__":
    if "snakemake" in globals():
        _from_snakemake(snakemake)  # noqa: F821
    else:
        sys.exit(main())
