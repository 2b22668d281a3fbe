"""Cost of a redistributing step against the same scheme's plain step, before and after
the potential's kept Cholesky factor and CG (issue #32), in one process.

The redistributing schemes solve, at every step, the potential's Laplacian
(``baselines.redistribution.PotentialSolver``, ``ddfv.redistribution.TangentialPotential``)
and then the positions' system with the drift (R4) / (R7). "before" is the
packages ``ddfv`` and ``baselines`` of commit ``BEFORE`` (a kept sparse LU
refined at every step, the drift built as a COO matrix), extracted by ``git
archive`` into a temporary directory as ``ddfv_before`` and ``baselines_before``
and driven by this harness; "after" is this tree. Each pair (plain scheme,
redistributing scheme) is stepped on the shrinking sphere at ``--level``
(Table 3.1's time step, every step of the run, or the first ``--steps``) by
:func:`mcfbench.running.driver.simulate`, both versions interleaved (the
order reversed on odd repeats), after a level-1 run of every variant (no
compilation or first call timed). Printed: the median CPU milliseconds per
step, the potential's share (its source, stiffness and solve:
``flow.timings["potential"]``, the before-DDFV's timed by wrapping its
``_potential_of``), the ratio of each redistributing step to the plain step
of the same version (target of issue #32: at most 2 at level 5), and after /
before. Usage::

    python benchmarks/bench_potential.py [--level 5] [--repeats 3] [--steps N]
        [--pairs cotan:cotan-redistribute ddfv-chord-carried:ddfv-chord-redistribute-carried]
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

from _harness import ROOT, footing, machine_line, median, one_core  # noqa: E402

from mcfbench.geometry.spheres import icosphere  # noqa: E402
from mcfbench.running.driver import simulate  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.schemes import get_scheme  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402
from mcfbench.storage.memory import tune_malloc  # noqa: E402

BEFORE = "acf8b58"
TARGET = 2.0
PAIRS = ["cotan:cotan-redistribute", "ddfv-chord-carried:ddfv-chord-redistribute-carried"]


def before_packages(tree):
    """``ddfv`` and ``baselines`` of :data:`BEFORE` as ``ddfv_before``, ``baselines_before``
    (their imports are relative) under ``tree``, importable; the DDFV potential timed."""
    archive = subprocess.run(["git", "archive", BEFORE, "ddfv", "baselines"], cwd=ROOT,
                             capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", tree], input=archive, check=True)
    for package in ("ddfv", "baselines"):
        Path(tree, package).rename(Path(tree, f"{package}_before"))
    sys.path.insert(0, tree)
    flow = importlib.import_module("ddfv_before.flow").Flow
    potential_of = flow._potential_of

    def timed(self, *args):
        clock = time.perf_counter()
        psi = potential_of(self, *args)
        self.timings["potential"] = (self.timings.get("potential", 0.0)
                                     + time.perf_counter() - clock)
        return psi
    flow._potential_of = timed


def variant(name, version):
    """The registry scheme ``name``, its flow class from this tree or from :data:`BEFORE`."""
    scheme = get_scheme(name)
    if version == "after":
        return scheme
    module, _, cls = scheme.flow.partition(":")
    package, _, rest = module.partition(".")
    return dataclasses.replace(scheme, flow=f"{package}_before.{rest}:{cls}")


def step_cost(scheme, level, steps):
    """``(CPU ms per step, potential ms per step)`` of one run of the sphere at ``level``."""
    sphere = get_problem("sphere")
    V, F = icosphere(level)
    tau = sphere.tau(level)
    steps = sphere.time_steps(tau) if steps is None else steps
    flow = scheme.make(V, F, tau)
    clock = time.process_time()
    traj = simulate(flow, steps, solver=Solver(), save_every=0)
    cpu = time.process_time() - clock
    if not traj.ok:
        raise RuntimeError(f"{scheme.name} ({scheme.flow}): {traj.message}")
    timings = flow.timings
    potential = timings.get("potential", timings.get("redistribution", 0.0))
    return 1e3 * cpu / steps, 1e3 * potential / steps


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=5)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--steps", type=int, default=None,
                        help="steps of each run (default: the whole run, t = 0.08)")
    parser.add_argument("--pairs", nargs="+", default=PAIRS,
                        help="plain:redistributing registry names")
    args = parser.parse_args(argv)
    tune_malloc()
    one_core()
    print(machine_line())
    pairs = [tuple(p.split(":")) for p in args.pairs]
    names = [name for pair in pairs for name in pair]
    versions = ("before", "after")
    with tempfile.TemporaryDirectory(prefix=f"potential-{BEFORE}-") as tree:
        before_packages(tree)
        schemes = {(n, v): variant(n, v) for n in names for v in versions}
        for scheme in schemes.values():                   # warm-up: compilation, caches
            step_cost(scheme, 1, None)
        cost = {key: [] for key in schemes}
        for repeat in range(args.repeats):
            keys = list(schemes) if repeat % 2 == 0 else list(schemes)[::-1]
            for key in keys:
                cost[key].append(step_cost(schemes[key], args.level, args.steps))
    ms = {k: median([c[0] for c in v]) for k, v in cost.items()}
    pot = {k: median([c[1] for c in v]) for k, v in cost.items()}
    print(f"sphere level {args.level}, CPU ms per step (median of {args.repeats}, "
          f"{'every step' if args.steps is None else f'{args.steps} steps'}), "
          f"before = {BEFORE}")
    print(f"{'scheme':34s} {'version':>7s} {'ms/step':>9s} {'potential':>10s} "
          f"{'x plain':>8s} {'after/before':>13s}  verdict")
    for plain, redistributing in pairs:
        for name in (plain, redistributing):
            for version in versions:
                key = (name, version)
                ratio = ms[key] / ms[(plain, version)]
                change = ms[(name, "after")] / ms[(name, "before")]
                verdict = ("" if name == plain else
                           "ok" if ratio <= TARGET else f"above {TARGET:g}")
                print(f"{name:34s} {version:>7s} {ms[key]:9.2f} {pot[key]:10.2f} "
                      f"{ratio:8.2f} {change if version == 'after' else float('nan'):13.2f}"
                      f"  {verdict}")
    print("potential: ms per step in the potential (R2)/(R3): source, stiffness, solve; "
          "part of the step.")
    print(footing())


if __name__ == "__main__":
    main()
