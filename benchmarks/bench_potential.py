"""Cost of a redistributing step against the same scheme's plain step (issues #30 and
#32: at most 2 x at level 5 of the sphere), before and after a change, in one process.

The redistributing schemes solve, at every step, the potential's Laplacian
(``baselines.redistribution.PotentialSolver``, ``ddfv.redistribution.TangentialPotential``)
and then the positions' system with the drift (R4) / (R7). "before" is the
packages ``ddfv``, ``baselines`` and ``kept_factor`` of commit ``--before``
(default :data:`BEFORE`: the potential solved to 1e-7, the drift's normal part by
a second sparse product), extracted by ``git archive`` into a temporary
directory as ``ddfv_before``, ``baselines_before`` and ``kept_factor_before``
(their imports of ``kept_factor`` rewritten) and driven by this harness;
"after" is this tree. Each pair (plain scheme, redistributing scheme) is
stepped on the shrinking sphere at ``--level`` (Table 3.1's time step, every
step of the run, or the first ``--steps``) by
:func:`mcfbench.running.driver.simulate`, both versions interleaved (the
order reversed on odd repeats), after a level-1 run of every variant (no
compilation or first call timed). Printed: the median CPU milliseconds per
step, the potential's share of the step (its source, stiffness and solve:
``flow.timings["potential"]``; 0 for flows that did not time it, e.g. the
DDFV of ``acf8b58``), the positions' BiCGStab iterations per step
(does the drift make them more?), the potential's CG iterations per step
and its factorisations, the ratio of each redistributing step to the plain
step of the same version (target: at most 2 at level 5), and after / before.
``--solvers``: instead, the choice of the potential's solver: the
systems (R2) of the first ``--steps`` (default 64) steps of ``cotan-redistribute``
at ``--level`` are recorded, then solved in sequence by each candidate (a
factorisation or preconditioner of the first system kept, each later system
from the previous solution or the extrapolation of the last two, to the
relative residual 1e-7; factorised again when the iteration fails): CPU ms
per solve (the first, the factorisation, apart), iterations per solve and
the largest relative difference to a direct solve. Algebraic multigrid
(``pyamg``, smoothed aggregation) is measured when ``pyamg`` is importable
(it is not a dependency). ``--profile``: instead, this tree's step taken apart:
CPU ms per step of each part (:data:`PARTS`: the potential's source,
stiffness and solve, the drift and its normal part, the system matrix, the
positions' BiCGStab, the rest) and the iterations per step, plain against
redistributing, over the first ``--steps`` steps. ``--tolerances``: the
potential's tolerance against the sphere's errors, orders, mesh quality and
CG iterations (levels 1 to ``--level``). Usage::

    python benchmarks/bench_potential.py [--level 5] [--repeats 3] [--steps N]
        [--before COMMIT]
        [--pairs cotan:cotan-redistribute ddfv-chord-carried:ddfv-chord-redistribute-carried]
    python benchmarks/bench_potential.py --solvers [--level 5] [--steps 64]
    python benchmarks/bench_potential.py --profile [--level 5] [--steps 64] [--repeats 3]
    python benchmarks/bench_potential.py --tolerances 1e-7 1e-4 1e-3 [--level 5]
    python benchmarks/bench_potential.py --check [5 7] [--repeats 3] [--steps N]

``--check``: the drift check of issue 46, this tree alone: plain and redistributing
steps interleaved at each level (level 5 the whole run, level 7 its first 64 steps
unless ``--steps``), absolute CPU ms per step, the ratio of the whole run (measured, or
for a partial run from its first step and the mean of its later steps, :func:`check`)
and "ok" or "DRIFT: above 2".
"""

import os

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
os.environ.setdefault("NUMBA_NUM_THREADS", "1")

import argparse  # noqa: E402
import dataclasses  # noqa: E402
import importlib  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
from _harness import ROOT, extract, footing, machine_line, median, one_core  # noqa: E402

from mcfbench.geometry.spheres import icosphere  # noqa: E402
from mcfbench.running.driver import simulate  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.schemes import get_scheme  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402
from mcfbench.storage.memory import tune_malloc  # noqa: E402

BEFORE = "660c097"
TARGET = 2.0
PAIRS = ["cotan:cotan-redistribute", "ddfv-chord-carried:ddfv-chord-redistribute-carried"]
PACKAGES = ("ddfv", "baselines", "kept_factor")


def before_packages(tree, commit):
    """:data:`PACKAGES` of ``commit`` (those it has) as ``ddfv_before``,
    ``baselines_before``, ``kept_factor_before`` under ``tree``, importable (``ddfv``
    and ``baselines`` import their own files relatively, ``kept_factor`` absolutely:
    rewritten)."""
    present = subprocess.run(["git", "ls-tree", "--name-only", commit], cwd=ROOT,
                             capture_output=True, check=True, text=True).stdout.split()
    packages = [p for p in PACKAGES if p in present]     # kept_factor: since 36cf514
    extract(commit, tree, *packages)
    for package in packages:
        Path(tree, package).rename(Path(tree, f"{package}_before"))
    for source in Path(tree).glob("*_before/*.py"):
        text = source.read_text()
        source.write_text(text.replace("from kept_factor import", "from kept_factor_before import"))
    sys.path.insert(0, tree)


def variant(name, version):
    """The registry scheme ``name``, its flow class from this tree or from the packages
    of the 'before' commit (:func:`before_packages`)."""
    scheme = get_scheme(name)
    if version == "after":
        return scheme
    module, _, cls = scheme.flow.partition(":")
    package, _, rest = module.partition(".")
    return dataclasses.replace(scheme, flow=f"{package}_before.{rest}:{cls}")


def step_cost(scheme, level, steps):
    """``(CPU ms per step, the potential's share of the step, BiCGStab iterations per
    step, the potential's CG iterations per step, its factorisations, CPU ms of the
    first step, CPU ms per later step)`` of one run of the sphere at ``level`` (the
    share: the flow's wall-clock timing of the potential over the run's wall-clock
    time, so that load on the machine cancels; the first step carries the potential's
    first factorisation, the later steps' mean is what a long run pays a step)."""
    sphere = get_problem("sphere")
    V, F = icosphere(level)
    tau = sphere.tau(level)
    steps = sphere.time_steps(tau) if steps is None else steps
    flow = scheme.make(V, F, tau)
    reached = []                                # CPU clock at every level reached

    def clocked(_):
        reached.append(time.process_time())
    clock, wall = time.process_time(), time.perf_counter()
    traj = simulate(flow, steps, solver=Solver(), save_every=0, observers=[clocked])
    end, wall = time.process_time(), time.perf_counter() - wall
    if not traj.ok:
        raise RuntimeError(f"{scheme.name} ({scheme.flow}): {traj.message}")
    potential = getattr(flow, "_potential_solver", getattr(flow, "_potential", None))
    cg = getattr(potential, "iterations", float("nan")) / steps   # not counted before 36cf514
    factorisations = getattr(potential, "factorisations", float("nan"))
    first = reached[1] - clock                  # with the run's set-up
    later = (end - reached[1]) / (steps - 1) if steps > 1 else float("nan")
    return (1e3 * (end - clock) / steps, flow.timings.get("potential", 0.0) / wall,
            float(traj.iterations.mean()), cg, factorisations, 1e3 * first, 1e3 * later)


#: the parts of a step timed by ``--profile``: (module, owner or None, attribute, label);
#: the potential's solve includes its stiffness's pinning, the rest of a step (geometry,
#: checks, bookkeeping) is the run's CPU time minus these
PARTS = {
    "baselines": [
        ("baselines.cotan", None, "redistribution_source", "potential: source (R2)"),
        ("baselines.redistribution", "PotentialSolver", "__call__", "potential: solve (R2)"),
        ("baselines.cotan", "CotanFlow", "_drifted_system",
         "drift (R4), normal part (R5), system (C3)"),
        ("baselines.laplacian", "CotanAssembler", "row_scaled", "system matrix (C3)"),
    ],
    "ddfv": [
        ("ddfv.flow", "Flow", "_geometry_at", "geometry"),
        ("ddfv.assembly", "Assembler", "system", "system matrix (2.10)"),
        ("ddfv.flow", None, "vertex_normals", "vertex normals"),
        ("ddfv.flow", None, "redistribution_source", "potential: source (R3)"),
        ("ddfv.flow", None, "potential_operators", "potential: h.V and stiffness K"),
        ("ddfv.redistribution", "TangentialPotential", "__call__", "potential: solve (R3)"),
        ("ddfv.flow", None, "drift_system", "drift (R7) + its D X"),
        ("ddfv.flow", None, "carry_t_vertices", "T-vertices carried"),
    ],
}


class _Timed:
    """The registry's solver, its CPU time kept (the positions' solve)."""

    can_overwrite_x0 = Solver.can_overwrite_x0

    def __init__(self):
        self.solver, self.seconds = Solver(), 0.0

    def __call__(self, *args, **kwargs):
        clock = time.process_time()
        result = self.solver(*args, **kwargs)
        self.seconds += time.process_time() - clock
        return result


def profile(pairs, level, steps, repeats):
    """CPU ms per step of each part of a step (:data:`PARTS`), plain and redistributing,
    over the first ``steps`` steps of the sphere at ``level`` (medians of ``repeats``
    runs, interleaved): the parts' functions wrapped by a CPU clock."""
    sphere = get_problem("sphere")
    V, F = icosphere(level)
    tau = sphere.tau(level)
    names = [name for pair in pairs for name in pair]
    spent = {}
    for package in {get_scheme(n).flow.partition(".")[0] for n in names}:
        for module, owner, attribute, label in PARTS[package]:
            target = importlib.import_module(module)
            target = getattr(target, owner) if owner else target
            setattr(target, attribute, _clocked(getattr(target, attribute), label, spent))
    rows = {name: [] for name in names}
    for repeat in range(repeats + 1):                     # the first: warm-up
        for name in (names if repeat % 2 == 0 else names[::-1]):
            flow, solver = get_scheme(name).make(V, F, tau), _Timed()
            spent.clear()
            clock = time.process_time()
            traj = simulate(flow, steps, solver=solver, save_every=0)
            total = time.process_time() - clock
            potential = getattr(flow, "_potential_solver", getattr(flow, "_potential", None))
            row = {label: spent.get(label, 0.0) for *_, label in
                   PARTS[get_scheme(name).flow.partition(".")[0]]}
            row["positions: BiCGStab"] = solver.seconds
            row["rest of the step"] = total - sum(row.values())
            row["step"] = total
            row["BiCGStab iterations"] = float(traj.iterations.sum())
            row["potential: CG iterations"] = (potential.iterations if potential is not None
                                               else 0.0)
            if repeat:
                rows[name].append(row)
    print(f"sphere level {level}, first {steps} steps, CPU ms per step (iterations per step), "
          f"median of {repeats}; the potential's solve includes its first factorisation; "
          f"rest of the step: geometry (cotan), checks, bookkeeping")
    for plain, redistributing in pairs:
        print(f"{'part':40s} {plain:>20s} {redistributing:>32s}")
        for label in rows[redistributing][0]:
            values = [median([r.get(label, 0.0) for r in rows[n]]) / steps
                      for n in (plain, redistributing)]
            scale = 1.0 if "iterations" in label else 1e3
            print(f"{label:40s} {scale * values[0]:20.3f} {scale * values[1]:32.3f}")
        print()


def _clocked(function, label, spent):
    def clocked(*args, **kwargs):
        clock = time.process_time()
        result = function(*args, **kwargs)
        spent[label] = spent.get(label, 0.0) + time.process_time() - clock
        return result
    return clocked


def tolerances(names, levels, rtols):
    """The potential's tolerance against the results: for each redistributing scheme and
    ``rtol`` (``POTENTIAL_RTOL`` of both packages), the sphere's Table 3.1 runs at
    ``levels`` (:func:`mcfbench.running.run.run`): L2 error, EOC, smallest angle, largest
    aspect ratio and the potential's CG iterations per step."""
    import baselines.redistribution
    import ddfv.redistribution

    from _harness import harness_run

    print(f"sphere, Table 3.1 setting, levels {levels}: the potential's tolerance")
    print(f"{'scheme':34s} {'rtol':>6s} {'level':>5s} {'L2 error':>13s} {'EOC':>6s} "
          f"{'min angle':>10s} {'max aspect':>10s} {'CG/step':>8s}")
    for name in names:
        for rtol in rtols:
            baselines.redistribution.POTENTIAL_RTOL = ddfv.redistribution.POTENTIAL_RTOL = rtol
            last = None
            for level in levels:
                result, flow = harness_run(name, level)
                error = result.metrics["l2_error"]
                potential = getattr(flow, "_potential_solver", getattr(flow, "_potential", None))
                eoc = np.log2(last / error) if last else float("nan")
                print(f"{name:34s} {rtol:6.0e} {level:5d} {error:13.6e} {eoc:6.3f} "
                      f"{result.min_angle:10.4f} {result.max_aspect:10.4f} "
                      f"{potential.iterations / result.steps_done:8.2f}")
                last = error


def recorded_systems(level, steps):
    """``(A, b)`` of the pinned potential systems of the first ``steps`` steps of
    ``cotan-redistribute`` on the sphere at ``level`` (as ``PotentialSolver`` forms them)."""
    from kept_factor import pinned

    sphere = get_problem("sphere")
    V, F = icosphere(level)
    flow = get_scheme("cotan-redistribute").make(V, F, sphere.tau(level))
    solver, systems = flow._potential_solver, []

    def record(L, mass, f):
        b = -mass * f
        b -= b.mean()
        keep = np.ones(len(b))
        keep[0] = b[0] = 0.0
        systems.append((pinned(L, keep)[1](), b))
        return solver(L, mass, f)
    flow._potential_solver = record
    simulate(flow, steps, solver=Solver(), save_every=0)
    return systems


def candidates():
    """name -> ``(factorise, extrapolate, max_iterations)``, ``factorise: A -> (method,
    solve)`` as :func:`kept_factor.factorise` (``solve`` exact or a preconditioner)."""
    import scipy.sparse as sp
    import scipy.sparse.linalg as spla

    from kept_factor import cholesky_solve

    def lu(method):
        return lambda A: (method, spla.splu(sp.csc_matrix(A)).solve)

    def jacobi(A):
        inverse = 1.0 / A.diagonal()
        return "cg", lambda r: inverse * r

    found = {"LU kept + refinement (before)": (lu("refinement"), False, 6),
             "LU kept + CG, extrapolated": (lu("cg"), True, 4),
             "Cholesky kept + CG": (lambda A: ("cg", cholesky_solve(A)), False, 4),
             "Cholesky kept + CG, extrapolated (after)": (lambda A: ("cg", cholesky_solve(A)),
                                                          True, 4),
             "Jacobi + CG, extrapolated": (jacobi, True, 5000)}
    try:
        import pyamg
    except ImportError:
        print("pyamg is not importable: algebraic multigrid not measured")
        return found

    def amg(A):
        hierarchy = pyamg.smoothed_aggregation_solver(sp.csr_matrix(A), symmetry="hermitian")
        return "cg", hierarchy.aspreconditioner(cycle="V").matvec
    found[f"AMG (pyamg {pyamg.__version__} SA) kept + CG, extrapolated"] = (amg, True, 100)
    return found


def solve_sequence(systems, factorise, extrapolate, max_iterations, rtol=1e-7):
    """``(first ms, ms per later solve, iterations per later solve, largest relative
    difference to a direct solve)`` of the systems solved in sequence by a
    :class:`kept_factor.KeptFactorSolver` (from the last solution, or the extrapolation
    of the last two)."""
    import scipy.sparse.linalg as spla

    from kept_factor import KeptFactorSolver

    solver = KeptFactorSolver(rtol, max_iterations, factorise)
    times, iterations, x, worst = [], [], None, 0.0
    for A, b in systems:
        clock, done = time.process_time(), solver.iterations
        x = solver.solve(b, A.dot, A, start=None if extrapolate else x, sequence="x")
        times.append(time.process_time() - clock)
        iterations.append(solver.iterations - done)
        exact = spla.spsolve(A.tocsc(), b)
        worst = max(worst, float(np.linalg.norm(x - exact) / np.linalg.norm(exact)))
    return 1e3 * times[0], 1e3 * median(times[1:]), float(np.mean(iterations[1:])), worst


def choose_solver(level, steps):
    systems = recorded_systems(level, steps)
    n = systems[0][0].shape[0]
    print(f"the potential (R2) of cotan-redistribute, sphere level {level}: {n} unknowns, "
          f"{len(systems)} systems in sequence; CPU ms")
    print(f"{'solver':52s} {'first':>8s} {'per solve':>10s} {'iterations':>11s} "
          f"{'vs direct':>10s}")
    for name, (factorise, extrapolate, cap) in candidates().items():
        first, per, its, worst = solve_sequence(systems, factorise, extrapolate, cap)
        print(f"{name:52s} {first:8.1f} {per:10.2f} {its:11.2f} {worst:10.1e}")
    print("iterations: of the kept factor or preconditioner on the later systems (LU "
          "refinement: passes); vs direct: largest |x - x_direct| / |x_direct|.")


def check(pairs, levels, steps, repeats):
    """This tree's ratios, redistributing step over plain step, at each of ``levels``
    (``steps``: level -> the steps of each run, None for the whole run), the pairs
    interleaved, medians of ``repeats``; printed with the absolute CPU ms and the
    verdict against :data:`TARGET` (issue 46: "drift" when a change makes a ratio pass
    it). A whole run's ratio is measured; a partial run's (level 7: 64 of 8 192 steps)
    is that of the whole run it begins, from its first step (the run's set-up and the
    potential's first factorisation: at level 7 3.5 s for cotan and 7.4 s for DDFV
    against 1.1 s for the plain schemes, most of a 64-step window) and its later
    steps' mean: ``(first + (N - 1) later)`` of each scheme,
    ``N`` the run's steps; the window's own ratio and the later steps' are printed
    beside it. Returns the verdict's ratios, ``{(redistributing, level): ratio}``."""
    names = [name for pair in pairs for name in pair]
    for name in names:                                     # warm-up: compilation, caches
        step_cost(get_scheme(name), 1, None)
    sphere = get_problem("sphere")
    ratios = {}
    print(f"{'level':>5s} {'plain':>20s} {'ms/step':>8s} {'redistributing':>32s} "
          f"{'ms/step':>8s} {'ratio':>6s} {'first ms':>17s} {'later ms/step':>15s} "
          f"{'later':>6s} {'window':>6s}  verdict")
    for level in levels:
        cost = {name: [] for name in names}
        for repeat in range(repeats):
            for name in (names if repeat % 2 == 0 else names[::-1]):
                cost[name].append(step_cost(get_scheme(name), level, steps.get(level)))
        total = sphere.time_steps(sphere.tau(level))
        for plain, redistributing in pairs:
            (a, a1, an), (b, b1, bn) = ([median([c[i] for c in cost[name]]) for i in (0, 5, 6)]
                                        for name in (plain, redistributing))
            ratio = b / a if steps.get(level) is None else \
                (b1 + (total - 1) * bn) / (a1 + (total - 1) * an)
            ratios[(redistributing, level)] = ratio
            print(f"{level:5d} {plain:>20s} {a:8.2f} {redistributing:>32s} {b:8.2f} "
                  f"{ratio:6.2f} {a1:8.1f} {b1:8.1f} {an:7.2f} {bn:7.2f} {bn / an:6.2f} "
                  f"{b / a:6.2f}  {'ok' if ratio <= TARGET else f'DRIFT: above {TARGET:g}'}")
    runs = ", ".join(f"level {lv}: {steps.get(lv) or 'all'} of "
                     f"{sphere.time_steps(sphere.tau(lv))}" for lv in levels)
    print(f"steps per run: {runs}; CPU ms per step, medians of {repeats}; ms/step: the "
          f"window's; ratio: the whole run's (measured, or first + (N - 1) later of a "
          f"partial run); first: the first step of plain, redistributing; later: the "
          f"mean of the others and their ratio; window: ms/step's ratio; "
          f"{machine_line()}")
    return ratios


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--steps", type=int, default=None,
                        help="steps of each run (default: the whole run, t = 0.08)")
    parser.add_argument("--pairs", nargs="+", default=PAIRS,
                        help="plain:redistributing registry names")
    parser.add_argument("--solvers", action="store_true",
                        help="compare the potential's solvers instead")
    parser.add_argument("--tolerances", nargs="+", type=float, default=None,
                        help="the potential's tolerances to compare on the sphere's levels "
                             "1 to --level instead")
    parser.add_argument("--profile", action="store_true",
                        help="time the parts of a step instead (this tree, --steps, default 64)")
    parser.add_argument("--check", type=int, nargs="*", default=None,
                        help="instead, this tree's ratios at these levels (default 5 7; "
                             "level 7 and above: the first 64 steps) against the target 2")
    parser.add_argument("--before", default=BEFORE,
                        help=f"the commit of the 'before' packages (default {BEFORE})")
    args = parser.parse_args(argv)
    tune_malloc()
    one_core()
    print(machine_line())
    if args.solvers:
        choose_solver(args.level, 64 if args.steps is None else args.steps)
        return
    pairs = [tuple(p.split(":")) for p in args.pairs]
    if args.check is not None:
        levels = args.check or [5, 7]
        check(pairs, levels, {lv: (64 if lv >= 7 else None) if args.steps is None
                              else args.steps for lv in levels}, args.repeats)
        return
    if args.tolerances:
        tolerances([pair[1] for pair in pairs], list(range(1, args.level + 1)), args.tolerances)
        return
    if args.profile:
        profile(pairs, args.level, 64 if args.steps is None else args.steps, args.repeats)
        return
    names = [name for pair in pairs for name in pair]
    versions = ("before", "after")
    with tempfile.TemporaryDirectory(prefix=f"potential-{args.before}-") as tree:
        before_packages(tree, args.before)
        schemes = {(n, v): variant(n, v) for n in names for v in versions}
        for scheme in schemes.values():                   # warm-up: compilation, caches
            step_cost(scheme, 1, None)
        cost = {key: [] for key in schemes}
        for repeat in range(args.repeats):
            keys = list(schemes) if repeat % 2 == 0 else list(schemes)[::-1]
            for key in keys:
                cost[key].append(step_cost(schemes[key], args.level, args.steps))
    ms, pot, its, cg, fac = ({k: median([c[i] for c in v]) for k, v in cost.items()}
                             for i in range(5))
    print(f"sphere level {args.level}, CPU ms per step (median of {args.repeats}, "
          f"{'every step' if args.steps is None else f'{args.steps} steps'}), "
          f"before = {args.before}")
    print(f"{'scheme':34s} {'version':>7s} {'ms/step':>9s} {'potential %':>12s} "
          f"{'BiCGStab':>9s} {'CG':>6s} {'LLT':>4s} {'x plain':>8s} {'after/before':>13s}  verdict")
    for plain, redistributing in pairs:
        for name in (plain, redistributing):
            for version in versions:
                key = (name, version)
                ratio = ms[key] / ms[(plain, version)]
                change = ms[(name, "after")] / ms[(name, "before")]
                verdict = ("" if name == plain else
                           "ok" if ratio <= TARGET else f"above {TARGET:g}")
                print(f"{name:34s} {version:>7s} {ms[key]:9.2f} {100 * pot[key]:12.1f} "
                      f"{its[key]:9.2f} {cg[key]:6.2f} {fac[key]:4.0f} {ratio:8.2f} "
                      f"{change if version == 'after' else float('nan'):13.2f}  {verdict}")
    print("potential %: the share of the step spent in the potential (R2)/(R3) (its "
          "source, stiffness and solve); BiCGStab: the positions' iterations per step; "
          "CG: the potential's iterations per step; LLT: its factorisations in the run; x "
          "plain: CPU time per step over the plain scheme's of the same version.")
    print(footing())


if __name__ == "__main__":
    main()
