"""The dumbbell through its pinch to both bulbs' extinction (issue #45's target): each
``NAME+surgery`` scheme on the dumbbell's levels, run to the flow's end, against the
axisymmetric reference continued through the pinch (``problems/dumbbell.py``).

    python benchmarks/dumbbell_surgery.py                        # levels 1-2, 3 schemes
    python benchmarks/dumbbell_surgery.py --levels 1 2 3 --schemes cotan+surgery

Prints one row per run: status (and the time of a breakdown), the cut (time, neck radius, area share removed), the
relative errors of the pinch time (the cut's ``t + r^2 / 2``), of the bulbs' extinction
time (the last component's) and of one bulb's volume at t = 0.12, 0.16, 0.2 (the larger
of the two bulbs' errors), and the CPU seconds. A run whose solver fails is continued
with the scheme's robust solver (as the matrix does), its row marked ``(robust)``.
"""

import argparse
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from mcfbench.geometry.collapse import component_volumes  # noqa: E402
from mcfbench.geometry.measures import vertex_components  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.run import run  # noqa: E402
from mcfbench.running.schemes import get_scheme  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402

SCHEMES = ("cotan+surgery", "bgn+surgery", "ddfv-chord-carried+surgery")


class BulbVolumes:
    """Every component's volume at the reference's times (the metric keeps the largest
    error only)."""

    def __init__(self, times):
        self.times, self.volumes = tuple(times), {}

    def __call__(self, flow):
        t = flow.n * flow.tau
        for s in self.times:
            if abs(t - s) < 1e-9:
                F = np.asarray(flow.faces)
                count, labels = vertex_components(F, len(flow.vertices))
                self.volumes[s] = component_volumes(flow.vertices, F, labels[F[:, 0]], count)


def row(scheme, level):
    problem = get_problem("dumbbell").with_settings(to_extinction=True, t_final=0.3)
    ref = problem.reference
    bulbs = BulbVolumes(ref["bulb_volume_times"])
    entry = get_scheme(scheme)
    result, traj, continued = run(entry, problem, level, observers=[bulbs],
                                  robust=Solver(method=entry.robust_solver))
    robust = continued is not None
    if robust:
        result = continued
    m = result.metrics
    cuts = [e for e in traj.events if e["event"] == "surgery"]     # before any failure
    volume_errors = [np.abs(bulbs.volumes[t] / v - 1).max() if t in bulbs.volumes else np.nan
                     for t, v in zip(ref["bulb_volume_times"], ref["bulb_volume"])]
    cut = (f"{cuts[0]['time']:.4f} {cuts[0]['neck_radius']:.4f} {len(cuts)}" if cuts
           else "-")
    status = result.status + (" (robust)" if robust else "")
    if result.status not in ("ok", "extinct"):
        status += f" t={result.t_failed:.4g}"
    return (f"{scheme:28s} {level:2d} {result.nF:6d} {status:20s} "
            f"{cut:>22s} {result.removed_area_share:9.2e} "
            f"{m.get('pinch_time_error', np.nan):+9.4f} "
            f"{m.get('extinction_time_error', np.nan):+9.4f} "
            + " ".join(f"{e:+9.4f}" for e in volume_errors)
            + f" {result.cpu_seconds:7.1f}")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--levels", nargs="+", type=int, default=[1, 2])
    parser.add_argument("--schemes", nargs="+", default=list(SCHEMES))
    args = parser.parse_args(argv)
    ref = get_problem("dumbbell").reference
    print(f"reference: pinch at {ref['pinch_time']}, bulbs extinct at {ref['extinction_time']}, "
          f"one bulb's volume {ref['bulb_volume']} at t = {ref['bulb_volume_times']}")
    print(f"{'scheme':28s} lv {'nodes':>6s} {'status':20s} {'cut t, r, cuts':>22s} "
          f"{'area rm':>9s} {'pinch':>9s} {'extinct':>9s} "
          + " ".join(f"{'V@' + str(t):>9s}" for t in ref["bulb_volume_times"]) + "    cpu s")
    for level in args.levels:
        for scheme in args.schemes:
            print(row(scheme, level), flush=True)


if __name__ == "__main__":
    main()
