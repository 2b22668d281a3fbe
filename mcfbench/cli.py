"""Command line: ``python -m mcfbench``, or the console scripts ``mcfbench`` and ``ddfv``.

``sphere-table``
    Table 3.1 for any scheme, next to the published values.
``study PROBLEM``
    Any scheme on any problem over its refinement series, with EOC.
``run MESH``
    Any scheme on a user's mesh, frames into an ``.npz`` or a ParaView
    collection (``.pvd``).
``export RUN.npz OUT.pvd`` (or ``OUT.gif``)
    The frames of a run (``run``'s ``.npz``, a matrix or gallery frames
    file) as a ParaView collection or an animation.
``report``
    The reproduction report from the result files.
``schemes``, ``problems``
    The registries.

Only the registries and the solver's method names are imported to build the
parser (``--help`` answers in a fraction of a second); each command imports
what it runs (the driver, the compiled kernels, libigl) when it runs.
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ddfv.variants import VARIANTS
from mcfbench.running.integrators import INTEGRATORS
from mcfbench.running.problems import PROBLEMS, Problem, get_problem
from mcfbench.running.schemes import MESH_STRATEGIES, SCHEMES, get_scheme
from mcfbench.running.solver import METHODS, ROBUST, Solver
from mcfbench.storage.atomic import check_writable, write_json
from mcfbench.storage.frames import save_frames
from mcfbench.storage.memory import tune_malloc
from mcfbench.storage.provenance import provenance
from mcfbench.storage.records import FIELDS


class _Parser(argparse.ArgumentParser):
    """argparse's parser, with a short error: one usage line (the positional
    arguments, no option list), the message, and where the options are."""

    def error(self, message):
        words = [a.dest.upper() + (" ..." if a.nargs == argparse.PARSER else "")
                 for a in self._actions if not a.option_strings]
        self.exit(2, f"usage: {self.prog} [options] {' '.join(words)}\n"
                     f"{self.prog}: error: {message}\n"
                     f"see `{self.prog} --help`\n")


def _positive_float(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}") from None
    if not (np.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def _count(text, least=0):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got {text!r}") from None
    if value < least:
        raise argparse.ArgumentTypeError(f"must be a whole number >= {least}, got {text}")
    return value


def _scheme_name(text):
    """A scheme name :func:`get_scheme` knows (derived names included), else the error
    naming the known ones."""
    try:
        get_scheme(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None
    return text


def _level(text):
    return _count(text, least=1)


def _common(parser, default_solver):
    parser.add_argument("--scheme", default="ddfv", type=_scheme_name, metavar="SCHEME",
                        help="scheme (default: ddfv; see `schemes`): a name of the registry, "
                             "NAME@INTEGRATOR, NAME+remesh, NAME@INTEGRATOR+remesh or "
                             "NAME+surgery")
    parser.add_argument("--variant", choices=list(VARIANTS),
                        help="DDFV variant: same as --scheme ddfv-VARIANT")
    parser.add_argument("--solver", choices=METHODS, default=default_solver,
                        help=f"linear solver (default: {default_solver})")
    parser.add_argument("--rtol", type=_positive_float, default=1e-9,
                        help="relative tolerance of the iterative solvers (default: 1e-9)")
    parser.add_argument("--maxiter", type=_level, default=1000,
                        help="iterations allowed per step (default: 1000)")
    parser.add_argument("--t-init", choices=("paper", "barycenter", "exact"),
                        help="DDFV: T-vertex initialisation (default: paper)")
    parser.add_argument("--integrator", choices=list(INTEGRATORS),
                        help="time integrator: the paper's semi-implicit Euler (default) "
                             "or linearly implicit BDF2 or BDF3")
    parser.add_argument("--warm-start", choices=("extrapolate", "previous"),
                        default="extrapolate",
                        help="initial guess of the solver: 2 X^n - X^{n-1} (default) or X^n")
    parser.add_argument("--on-defect", choices=("stop", "record"), default="stop",
                        help="an invalid state (T-vertex escaped, triangle inverted, mesh "
                             "degenerated) ends the run (stop, default) or is recorded")
    parser.add_argument("--threads", type=_level, default=1,
                        help="threads of the solver, of the schemes' compiled passes "
                             "(DDFV, cotan's and BGN's families) and of the checks "
                             "(default: 1)")
    parser.add_argument("--force", action="store_true",
                        help="run even when the run's estimated memory is above the "
                             "machine's available memory (refused otherwise)")


def build_parser():
    parser = _Parser(
        prog="python -m mcfbench",
        description="Benchmark of mean curvature flow schemes (DDFV and baselines).")
    commands = parser.add_subparsers(dest="command", required=True)

    table = commands.add_parser("sphere-table", help="Table 3.1 (shrinking unit sphere)")
    table.add_argument("--levels", type=_level, nargs="+", default=[1, 2, 3, 4, 5],
                       help="icosphere refinement levels >= 1 (default: 1 2 3 4 5)")
    table.add_argument("--csv", type=Path, help="also write the table as CSV "
                       "(and its provenance as CSV.json)")
    _common(table, "bicgstab")

    study = commands.add_parser("study", help="a scheme on a problem's refinement series")
    study.add_argument("problem", choices=list(PROBLEMS))
    study.add_argument("--levels", type=_level, nargs="+", help="default: the problem's")
    study.add_argument("--csv", type=Path, help="also write the table as CSV")
    _common(study, "bicgstab")

    flow = commands.add_parser("run", help="run a scheme on a triangle mesh file "
                               "(boundary vertices are held fixed)")
    flow.add_argument("mesh", type=Path, help="OBJ, OFF, PLY or STL file")
    step = flow.add_mutually_exclusive_group(required=True)
    step.add_argument("--tau", type=_positive_float, help="time step")
    step.add_argument("--tau-edge", type=_positive_float, metavar="C",
                      help="time step C * (mean edge length)^2")
    flow.add_argument("--steps", type=_level, required=True, help="number of time steps")
    flow.add_argument("--save-every", type=_count, default=1, metavar="K",
                      help="keep every K-th step as a frame (default: 1, every step; "
                           "0: first and last only)")
    flow.add_argument("--out", type=Path, required=True,
                      help="output file: .npz (the frames and the run's data) or .pvd (a "
                           "ParaView collection, one .vtu per frame in the folder OUT/)")
    flow.add_argument("--movie", type=Path, help="also an animation of the saved frames "
                      "(.gif; one camera and scale, time and status on each frame)")
    _common(flow, ROBUST)

    export = commands.add_parser("export", help="a run's frames (.npz of run, matrix or "
                                 "gallery) as a ParaView collection (.pvd) or a GIF")
    export.add_argument("source", type=Path, help="the run's .npz")
    export.add_argument("out", type=Path, help="the collection (.pvd; its .vtu files go to "
                        "the folder OUT/ next to it) or an animation (.gif)")

    report = commands.add_parser("report", help="the reproduction report from the result "
                                 "files (what the pipeline's rule reproduction_report does)")
    report.add_argument("--results", type=Path, default=Path("results"))
    report.add_argument("--paper", type=Path, default=Path("paper"))
    report.add_argument("--readme", type=Path, default=Path("ddfv/README.md"))
    report.add_argument("--out", type=Path, help="report folder (default: RESULTS/paper)")
    report.add_argument("--beyond", type=Path,
                        help="beyond-the-paper folder (default: RESULTS/beyond)")
    report.add_argument("--log", type=Path, help="default: OUT/report.log")

    commands.add_parser("schemes", help="list the schemes")
    commands.add_parser("problems", help="list the problems")
    return parser


def main(argv=None):
    args = build_parser().parse_args(argv)
    tune_malloc()
    try:
        return COMMANDS[args.command](args)
    except ValueError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    except OSError as err:          # "FILE: Permission denied", not "[Errno 13] ..."
        text = f"{err.filename}: {err.strerror}" if err.filename and err.strerror else err
        print(f"error: {text}", file=sys.stderr)
        return 2


def _terminal():
    """Progress bars only when standard error is a terminal (none in logs, pipes, jobs)."""
    return sys.stderr.isatty()


def _scheme(args):
    if args.variant is not None:
        name = "ddfv" if args.variant == "paper" else f"ddfv-{args.variant}"
        return get_scheme(name)
    return get_scheme(args.scheme)


def _options(args, scheme):
    """Run options: the solver and the DDFV-only settings that were given."""
    options = {"solver": Solver(args.solver, args.rtol, args.maxiter, threads=args.threads),
               "integrator": args.integrator, "warm_start": args.warm_start,
               "on_defect": args.on_defect, "threads": args.threads, "force": args.force}
    ddfv_only = {"t_init": args.t_init}
    given = {k: v for k, v in ddfv_only.items() if v is not None}
    if given and not scheme.extra_points:
        raise ValueError(f"--{next(iter(given)).replace('_', '-')} applies to the DDFV "
                         f"schemes only, not to {scheme.name}")
    return {**options, **given}


def _settings(args, scheme):
    return {"command": args.command, "scheme": scheme.name, "solver": args.solver,
            "rtol": args.rtol, "maxiter": args.maxiter, "t_init": args.t_init,
            "integrator": args.integrator or scheme.integrator, "warm_start": args.warm_start,
            "on_defect": args.on_defect,
            "threads": args.threads}


def _sphere_table(args):
    from mcfbench.studies.convergence.job import sphere_table

    scheme = _scheme(args)
    if args.csv:
        check_writable(args.csv)
    table = sphere_table(args.levels, scheme.name, progress=_terminal(),
                         **_options(args, scheme))
    print(format_table(table))
    _print_timing_note(table)
    if args.csv:
        _write_csv(args.csv, table, {**_settings(args, scheme), "levels": args.levels})
    _print_failures(table)
    return 0 if (table["status"] == "ok").all() else 1


def _study(args):
    from mcfbench.studies.matrix.tables import is_error
    from mcfbench.running.run import level_sweep

    scheme, problem = _scheme(args), get_problem(args.problem)
    if args.csv:
        check_writable(args.csv)
    table = level_sweep(scheme.name, problem, args.levels, progress=_terminal(),
                        **_options(args, scheme))
    metrics = [c for c in table.columns if c not in FIELDS and not c.startswith("eoc_")]
    # an order of convergence only of an error (its exact value zero), as in the matrix
    table = table.drop(columns=[f"eoc_{m}" for m in metrics if not is_error(m)])
    columns = ["level", "nV", "h", "tau", "N", "steps_done", "status",
               *[c for c in table.columns if c.startswith("eoc_")], *metrics,
               "iterations", "min_angle", "cpu_seconds"]
    print(f"{scheme.label} on {problem.label} ({problem.exact})")
    print(table[list(dict.fromkeys(columns))].to_string(index=False, float_format="%.4g"))
    _print_timing_note(table)
    if args.csv:
        _write_csv(args.csv, table, {**_settings(args, scheme), "problem": problem.name,
                                     "levels": args.levels})
    _print_failures(table)
    return 0 if (table["status"] == "ok").all() else 1


def _write_csv(path, table, config):
    from mcfbench.presentation.tables import csv
    from mcfbench.storage.atomic import write_text

    write_text(path, csv(table))
    write_json(f"{path}.json", provenance(config))
    print(f"wrote {path}")


def _print_timing_note(table):
    """Under a table: the levels whose CPU time is the best of repeated runs."""
    from mcfbench.running.run import SHORT_RUN

    short = table[table["timing_repeats"] > 1]
    if len(short):
        runs = ", ".join(f"{r.level} ({r.timing_repeats} runs)" for r in short.itertuples())
        print(f"CPU seconds of level(s) {runs}: the best of repeated runs (a run under "
              f"{SHORT_RUN * 1000:g} ms is timed again, as timeit does); every level's "
              f"time excludes the warm-up (compilation, first calls)")


def _print_failures(table):
    for row in table.itertuples():
        if row.status != "ok":
            print(f"error: level {row.level}: {row.message}", file=sys.stderr)


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


OUTPUTS = (".npz", ".pvd")
"""What ``run --out`` writes, by suffix."""


CONTINUATIONS = ("surgery", "reextracted", "refused")
"""The events of a ``NAME+surgery`` run that ``run`` prints (the driver's ``events``)."""


def _continuation(event):
    """One line of a continuation's event: when, what, where, the components before
    and after, the share of the area removed (or why it was refused)."""
    head = f"step {event['step']} (t = {event['time']:.4g}): {event['event']}"
    if event["event"] == "refused":
        return f"{head} by {event['by']}: {event['why']}"
    where = ", ".join(f"{x:.4g}" for x in event["where"])
    return (f"{head} at ({where}), components {event['components_before']} -> "
            f"{event['components_after']}, {100 * event['area_share']:.3g} % of the "
            "initial area removed")


def _run(args):
    from mcfbench.geometry.mesh import summarize
    from mcfbench.geometry.mesh_files import read_mesh
    from mcfbench.running.run import run

    scheme = _scheme(args)
    options = _options(args, scheme)
    check_writable(args.out)
    if args.out.suffix not in OUTPUTS:
        raise ValueError(f"--out {args.out}: the output is an .npz archive or a ParaView "
                         f"collection; name it *.npz or *.pvd")
    if args.movie is not None:
        check_writable(args.movie)
        if args.movie.suffix.lower() != ".gif":
            raise ValueError(f"--movie {args.movie}: the animation is a GIF; name it *.gif")
    V, F, intake = read_mesh(args.mesh)
    for note in intake.notes():
        print(f"note: {note}")
    print(f"mesh: {summarize(V, F)}")
    problem = Problem.user_mesh(args.mesh.name, args.steps, args.tau_edge or 1.0)
    tau = args.tau
    print(f"scheme {scheme.name}, solver {args.solver}"
          f"{' (the robust default)' if args.solver == ROBUST else f' (rtol {args.rtol:g})'}, "
          f"tau {tau if tau else problem.tau(0, (V, F)):.4g}, {args.steps} steps")
    result, traj = run(scheme, problem, 0, tau=tau, mesh=(V, F), save_every=args.save_every,
                       progress=_terminal(), **options)
    config = {**_settings(args, scheme), "mesh": str(args.mesh), "tau": result.tau,
              "steps": args.steps, "save_every": args.save_every}
    arrays = dict(traj.frames, faces=traj.faces, vertex_map=intake.kept, t=traj.t,
                  steps=traj.steps, iterations=traj.iterations,
                  t_min_barycentric=np.array(result.series["t_min_barycentric"]),
                  status=traj.status, message=traj.message, failed_step=traj.failed_step,
                  scheme=scheme.name, defects=json.dumps(traj.defects),
                  provenance=json.dumps(provenance(config)))
    arrays = {k: np.asarray(v) for k, v in arrays.items()}
    if args.out.suffix == ".pvd":
        from mcfbench.presentation.paraview_export import export_pvd, run_provenance

        export_pvd(arrays, args.out, run_provenance(arrays))
    else:
        save_frames(args.out, arrays)
    print(f"wrote {args.out}: {len(traj.t)} frames, {traj.steps_done} steps, "
          f"{int(traj.iterations.sum())} solver iterations, smallest angle "
          f"{result.min_angle:.3g} deg"
          + (f", min T barycentric {result.t_min_barycentric:.3f}"
             if scheme.extra_points else ""))
    if args.movie is not None:
        from mcfbench.presentation.movie import write_movie

        write_movie(arrays, args.movie, title=f"{scheme.label} on {args.mesh.name}")
        print(f"wrote {args.movie}: {len(traj.t)} frames")
    for event in traj.events:
        if event["event"] in CONTINUATIONS:
            print(_continuation(event))
    if traj.status == "extinct":         # the flow's own end, not an error
        print(f"the flow ended: {traj.message}")
    elif traj.status != "ok":
        print(f"error: {traj.message} (frames up to step {traj.steps[-1]} kept)",
              file=sys.stderr)
        return 1
    return 0


def _export(args):
    from mcfbench.presentation.paraview_export import (
        RUN_KEYS,
        export_file,
        load_frames_file,
        run_provenance,
    )

    check_writable(args.out)
    if args.out.suffix == ".gif":
        from mcfbench.presentation.movie import write_movie

        arrays = load_frames_file(args.source)
        # the status as the .pvd export reads it: the .npz's own, or its record's
        run = run_provenance(arrays, args.source)
        scheme = run.get("scheme", args.source.parent.name)
        write_movie({**arrays, **{key: run[key] for key in RUN_KEYS if key in run}}, args.out,
                    title=f"{scheme}: {args.source.name}")
        print(f"wrote {args.out}: {len(arrays['t'])} frames")
        return 0
    if args.out.suffix != ".pvd":
        raise ValueError(f"{args.out}: the export is a ParaView collection (.pvd) or an "
                         f"animation (.gif); name it *.pvd or *.gif")
    files = export_file(args.source, args.out)
    print(f"wrote {args.out}: {len(files) - 1} frame files in {args.out.parent / args.out.stem}/")
    return 0


def _report(args):
    from mcfbench.storage.logs import setup_logging
    from mcfbench.studies.figures.experiments import EXPERIMENTS
    from mcfbench.studies.report.page import ReportError, Sources, build

    sources = Sources(results=args.results, paper=args.paper, readme=args.readme,
                      out=args.out or args.results / "paper",
                      beyond=args.beyond or args.results / "beyond", experiments=EXPERIMENTS)
    log = setup_logging(args.log or sources.out / "report.log")
    try:
        build(sources, log=log)
    except ReportError as err:
        log.error("%s", err)
        return 1
    return 0


def _origin(entry):
    """`` [distribution version]`` of an installed package's scheme or problem, else ``""``."""
    source = entry.source
    return f" [{source['distribution']} {source['version']}]" if source else ""


def _schemes(args):
    width = max(map(len, SCHEMES))
    for scheme in SCHEMES.values():
        print(f"{scheme.name:{width}}  {scheme.description}{_origin(scheme)}")
    print("\nEach also as NAME@INTEGRATOR (" + ", ".join(i for i in INTEGRATORS if i != "euler")
          + "), NAME+STRATEGY and NAME@INTEGRATOR+STRATEGY:")
    for strategy, description in MESH_STRATEGIES.items():
        print(f"  +{strategy}  {description}")
    return 0


def _problems(args):
    width = max(map(len, PROBLEMS))
    for problem in PROBLEMS.values():
        print(f"{problem.name:{width}}  {problem.label}: {problem.exact}{_origin(problem)}")
    return 0


COMMANDS = {"sphere-table": _sphere_table, "study": _study, "run": _run, "export": _export,
            "report": _report, "schemes": _schemes, "problems": _problems}
