"""Command line: ``python -m ddfv sphere-table`` and ``python -m ddfv run``."""

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from .meshio import read_mesh
from .provenance import provenance
from .sphere import sphere_table
from .stepping import DEFAULT_RTOL, WARM_STARTS, simulate
from .t_vertices import METHODS
from .variants import VARIANTS, variant_options


def _positive_float(text):
    value = float(text)
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def _count(text):
    value = int(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 0, got {text}")
    return value


def _solver_options(parser):
    parser.add_argument("--t-init", choices=METHODS, default="paper",
                        help="T-vertex initialisation (default: paper)")
    parser.add_argument("--rtol", type=_positive_float, default=DEFAULT_RTOL,
                        help=f"BiCGStab relative tolerance (default: {DEFAULT_RTOL:g})")
    parser.add_argument("--warm-start", choices=WARM_STARTS, default="extrapolate",
                        help="BiCGStab initial guess (default: extrapolate)")
    parser.add_argument("--maxiter", type=_count, default=1000,
                        help="BiCGStab iterations allowed per step (default: 1000)")
    parser.add_argument("--variant", choices=list(VARIANTS), default="paper",
                        help="scheme variant (default: paper; see ddfv/variants.py)")


def build_parser():
    parser = argparse.ArgumentParser(
        prog="python -m ddfv",
        description="DDFV scheme for mean curvature flow of surfaces.")
    commands = parser.add_subparsers(dest="command", required=True)

    table = commands.add_parser(
        "sphere-table", help="reproduce Table 3.1 (shrinking unit sphere)")
    table.add_argument("--levels", type=int, nargs="+", default=[1, 2, 3, 4, 5],
                       help="icosphere refinement levels (default: 1 2 3 4 5)")
    table.add_argument("--csv", type=Path, help="also write the table as CSV "
                       "(and its provenance as CSV.json)")
    _solver_options(table)

    run = commands.add_parser("run", help="run the flow on a triangle mesh "
                              "(boundary vertices are held fixed)")
    run.add_argument("mesh", type=Path, help="OBJ, OFF, PLY or STL file")
    run.add_argument("--tau", type=_positive_float, required=True, help="time step")
    run.add_argument("--steps", type=_count, required=True, help="number of time steps")
    run.add_argument("--save-every", type=_count, default=1,
                     help="keep every K-th step as a frame (0: first and last only)")
    run.add_argument("--out", type=Path, required=True, help="output .npz file")
    _solver_options(run)
    return parser


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        if args.command == "sphere-table":
            return _sphere_table(args)
        return _run(args)
    except (ValueError, FileNotFoundError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


def _options(args):
    return {"t_init": args.t_init, "rtol": args.rtol, "warm_start": args.warm_start,
            "maxiter": args.maxiter}


def _sphere_table(args):
    if any(level < 0 for level in args.levels):
        raise ValueError(f"levels must be >= 0, got {args.levels}")
    table = sphere_table(args.levels, variant=args.variant, **_options(args))
    print(format_table(table))
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        table.to_csv(args.csv, index=False)
        config = {"command": "sphere-table", "levels": args.levels,
                  "variant": args.variant, **_options(args)}
        Path(f"{args.csv}.json").write_text(json.dumps(provenance(config), indent=2))
        print(f"wrote {args.csv}")
    return 0 if (table["status"] == "ok").all() else 1


def format_table(table):
    """Table 3.1, ours next to the paper's, as text."""
    head = (f"{'nV':>6} {'nF':>6} {'nT':>6} {'tau':>10} {'N':>4} | "
            f"{'L2 error':>10} {'paper':>9} {'ratio':>6} | {'iter':>5} {'paper':>5} | "
            f"{'EOC':>5} {'paper':>5} | {'CPU s':>7} {'paper':>7} | status")
    lines = [head, "-" * len(head)]
    for r in table.itertuples():
        lines.append(
            f"{r.nV:6d} {r.nF:6d} {r.nT:6d} {r.tau:10.8f} {r.N:4d} | "
            f"{r.l2_error:10.4e} {r.paper_l2_error:9.2e} {r.l2_ratio:6.3f} | "
            f"{r.iterations:5d} {_int(r.paper_iterations):>5} | "
            f"{_num(r.eoc, 3):>5} {_num(r.paper_eoc, 2):>5} | "
            f"{r.cpu_seconds:7.2f} {_num(r.paper_cpu_seconds, 2):>7} | {r.status}")
    return "\n".join(lines)


def _num(x, digits):
    return "" if x is None or np.isnan(x) else f"{x:.{digits}f}"


def _int(x):
    return "" if x is None or np.isnan(x) else f"{int(x)}"


def _run(args):
    V, F = read_mesh(args.mesh)
    traj = simulate(V, F, args.tau, args.steps, save_every=args.save_every,
                    progress=True, **variant_options(args.variant), **_options(args))
    config = {"command": "run", "mesh": str(args.mesh), "tau": args.tau,
              "steps": args.steps, "save_every": args.save_every,
              "variant": args.variant, **_options(args)}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        args.out, F=traj.F, T=traj.T, faces=traj.faces, t=traj.t, steps=traj.steps,
        iterations=traj.iterations, t_min_barycentric=traj.t_min_barycentric,
        status=traj.status, message=traj.message, failed_step=traj.failed_step,
        variant=args.variant,
        provenance=json.dumps(provenance(config)))
    done = len(traj.iterations)
    print(f"wrote {args.out}: {len(traj.t)} frames, {done} steps, "
          f"{int(traj.iterations.sum())} BiCGStab iterations, "
          f"min T barycentric {traj.t_min_barycentric.min():.3f}")
    if traj.status != "ok":
        print(f"error: {traj.message} (frames up to step {traj.steps[-1]} kept)",
              file=sys.stderr)
        return 1
    return 0
