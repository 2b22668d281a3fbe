"""How much the mesh area of each scheme grows above its running minimum, on the problems
with an exact or reference answer: the measurement behind the tolerance of the driver's
area check (``mcfbench.geometry.invariants.AREA_TOL``).

    python benchmarks/area_fluctuation.py                     # levels 1-2, both integrators
    python benchmarks/area_fluctuation.py --levels 1 --problems catenoid --schemes ddfv

Mean curvature flow never increases the area. For every run (scheme x integrator x
problem x level, the driver's checks on) it prints the largest relative growth of the
area of the mesh over its smallest earlier value, ``max_n (A^n - min_{k<n} A^k) /
min_{k<n} A^k`` (negative: the area fell at every step), the status, and at the end the
largest growth among the runs that ended ``ok`` and the runs the check stopped. The
runs go on to the problem's final time; a run the area check stopped shows a growth
just above the tolerance.
"""

import argparse
import itertools
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from mcfbench.geometry import metrics  # noqa: E402
from mcfbench.geometry.invariants import AREA_TOL  # noqa: E402
from mcfbench.running.problems import PROBLEMS  # noqa: E402
from mcfbench.running.run import run  # noqa: E402
from mcfbench.running.schemes import SCHEMES  # noqa: E402

ANSWERED = ("sphere", "perturbed_sphere", "remeshed_sphere", "anisotropic_sphere",
            "catenoid", "hemisphere", "enneper", "flat_patch", "torus", "dumbbell",
            "angenent")
"""The problems with an exact or a reference answer."""


class _Areas:
    """Observer: the mesh area at every time level."""

    def __init__(self):
        self.values = []

    def __call__(self, flow):
        self.values.append(metrics.area(flow.vertices, flow.faces))


def growth(areas):
    """Largest relative growth of ``areas`` over its running minimum (-inf: fewer than two)."""
    a = np.asarray(areas, dtype=float)
    if len(a) < 2:
        return -np.inf
    low = np.minimum.accumulate(a)[:-1]
    return float(((a[1:] - low) / low).max())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problems", nargs="+", default=list(ANSWERED), choices=PROBLEMS)
    parser.add_argument("--levels", nargs="+", type=int, default=[1, 2])
    parser.add_argument("--schemes", nargs="+", default=list(SCHEMES), choices=SCHEMES)
    parser.add_argument("--integrators", nargs="+", default=["euler", "bdf2"])
    args = parser.parse_args(argv)
    print(f"{'problem':20} {'lvl':>3} {'scheme':32} {'integr':6} {'growth':>10}  status")
    stopped, passed = [], []
    for problem, level, integrator, scheme in itertools.product(
            args.problems, args.levels, args.integrators, args.schemes):
        if level not in PROBLEMS[problem].levels:
            continue
        areas = _Areas()
        result, _ = run(scheme, problem, level, integrator=integrator, observers=[areas])
        g = growth(areas.values)
        (passed if result.status == "ok" else stopped).append((g, problem, level, scheme,
                                                               integrator, result.status))
        print(f"{problem:20} {level:3d} {scheme:32} {integrator:6} {g:10.2e}  {result.status}",
              flush=True)
    worst = max(passed, default=None)
    print(f"\ntolerance AREA_TOL = {AREA_TOL:g}; runs ending ok: {len(passed)}, largest growth "
          + (f"{worst[0]:.2e} ({', '.join(map(str, worst[1:5]))})" if worst else "-"))
    grew = [s for s in stopped if s[-1] == "area_grew"]
    print(f"runs the area check stopped: {len(grew)}"
          + "".join(f"\n  {p} level {lvl} {s}@{i}" for _, p, lvl, s, i, _ in grew))


if __name__ == "__main__":
    main()
