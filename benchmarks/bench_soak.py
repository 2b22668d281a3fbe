"""Soak: every scheme on the gallery's meshes for many steps, peak memory per run (issue #24).

Each run is :func:`mcfbench.running.run.run` of one scheme on one mesh as the gallery runs
it (``tau = C h^2``, the robust solver, ``C = 0.1``) but for many steps and with
``on_defect="record"``, so a run goes on past an escaped T-vertex or an inverted
triangle and only stops at a solver failure or a collapsed component. Each run is a
FRESH child process (pinned to one core, one BLAS thread, glibc's malloc tuned) so that
its peak resident memory (``ru_maxrss``) is its own; an exception in a run (a traceback
the harness should have turned into a status) is reported as ``exception`` with its
type, not hidden.

    python benchmarks/bench_soak.py                         # the gallery's own meshes, 400 steps
    python benchmarks/bench_soak.py --meshes DIR --steps 2000
    python benchmarks/bench_soak.py --schemes cotan bgn --steps 50 --only perturbed_sphere

The meshes are those of ``snakemake gallery`` without ``meshes=``:
:func:`mcfbench.studies.gallery.generated_meshes` (the registry's real-world-like
problems at the middle level of their series), or every mesh file of ``--meshes DIR``.
The table: per mesh and scheme, the status (first defect), every status recorded, the
steps done, wall seconds and the peak RSS of the run's process.
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
             "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from _harness import machine_line, one_core  # noqa: E402


def meshes(folder=None):
    """``{name: how to get it}``: the gallery's generated meshes, or the files of ``folder``."""
    if folder is None:
        from mcfbench.studies.gallery.plan import generated_meshes

        return {Path(name).stem: ("generated", entry) for name, entry in generated_meshes().items()}
    from mcfbench.studies.gallery.plan import MESH_SUFFIXES

    return {p.stem: ("file", str(p)) for p in sorted(Path(folder).iterdir())
            if p.suffix.lower() in MESH_SUFFIXES}


def load(how):
    from mcfbench.geometry.mesh import validate_mesh

    kind, what = how
    if kind == "file":
        from mcfbench.geometry.mesh_files import read_mesh

        V, F, _ = read_mesh(what)
        return V, F
    from mcfbench.geometry.surfaces import make_surface
    from mcfbench.running.problems import get_problem

    kind, name, level = what
    return validate_mesh(*(get_problem(name).mesh(level) if kind == "problem"
                           else make_surface(name)))


def child(scheme, how, steps, C):
    """One run in this (fresh) process; its result as a dict."""
    from mcfbench.storage.memory import tune_malloc

    tune_malloc()
    from mcfbench.geometry import metrics
    from mcfbench.running.problems import Problem
    from mcfbench.running.run import run
    from mcfbench.running.solver import Solver

    V, F = load(how)
    problem = Problem.user_mesh("soak", steps, C)
    wall = time.perf_counter()
    out = {"nV": len(V), "nF": len(F), "tau": C * metrics.mean_edge_length(V, F) ** 2}
    try:
        result, traj = run(scheme, problem, 0, mesh=(V, F), solver=Solver("direct"),
                           on_defect="record", samples=10)
        out.update(status=result.status, steps_done=result.steps_done,
                   recorded=[f"{d['status']}@{d['step']}" for d in traj.defects],
                   message=result.message, iterations=result.iterations)
    except Exception as err:  # noqa: BLE001 (a soak reports what a run raised)
        out.update(status="exception", steps_done=-1, recorded=[],
                   message=f"{type(err).__name__}: {err}", iterations=0)
    out["wall"] = time.perf_counter() - wall
    out["peak_rss_mb"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    return out


def main(argv=None):
    from mcfbench.running.schemes import SCHEMES

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--meshes", help="folder of mesh files (default: the gallery's own)")
    parser.add_argument("--schemes", nargs="+", default=list(SCHEMES), choices=list(SCHEMES))
    parser.add_argument("--steps", type=int, default=400)
    parser.add_argument("--C", type=float, default=0.1, help="tau = C (mean edge)^2")
    parser.add_argument("--only", nargs="+", help="mesh names to run (default: all)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        spec = json.loads(args.child)
        print(json.dumps(child(spec["scheme"], spec["how"], spec["steps"], spec["C"])))
        return 0
    one_core()
    found = meshes(args.meshes)
    if args.only:
        found = {k: v for k, v in found.items() if k in args.only}
    print(f"# Soak: {len(args.schemes)} scheme(s) x {len(found)} mesh(es), {args.steps} "
          f"steps, tau = {args.C:g} h^2, direct solver, on_defect=record")
    print(f"# {machine_line()}")
    header = ("mesh", "scheme", "nV", "status", "recorded", "steps", "wall s", "peak RSS MB")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    rows = []
    for name, how in found.items():
        for scheme in args.schemes:
            spec = json.dumps({"scheme": scheme, "how": how, "steps": args.steps, "C": args.C})
            done = subprocess.run([sys.executable, __file__, "--child", spec],
                                  capture_output=True, text=True)
            try:
                r = json.loads(done.stdout.strip().splitlines()[-1])
            except (IndexError, json.JSONDecodeError):
                r = {"nV": "?", "status": "crashed", "recorded": [], "steps_done": -1,
                     "wall": float("nan"), "peak_rss_mb": float("nan"),
                     "message": done.stderr.strip().splitlines()[-1] if done.stderr else ""}
            rows.append((name, scheme, r))
            print(f"| {name} | {scheme} | {r['nV']} | {r['status']} | "
                  f"{', '.join(r['recorded']) or '–'} | {r['steps_done']}/{args.steps} | "
                  f"{r['wall']:.2f} | {r['peak_rss_mb']:.0f} |", flush=True)
    bad = [(n, s, r) for n, s, r in rows if r["status"] in ("exception", "crashed")]
    for n, s, r in bad:
        print(f"# {s} on {n}: {r['status']}: {r['message']}")
    print(f"# {len(bad)} run(s) raised; peak RSS is each run's own process "
          "(imports and compiled kernels included, about 150-200 MB of it).")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
