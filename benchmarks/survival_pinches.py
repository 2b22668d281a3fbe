"""Are the survival study's breakdowns on meshes without thin features the flow's own
pinch? (issue #44)

    python benchmarks/survival_pinches.py [MESH ...] [--scheme S]
        (default: double_torus_marching32 quadknot kitten_decimated20, bgn+remesh)

For each mesh of the raw corpus: the inner thickness of its triangles
(:func:`mcfbench.geometry.thickness.triangle_thickness`) in mean edges ``h`` (quantiles
1, 5 and 50 %), the share of its area thinner than ``2 sqrt(8) h`` (a tube of diameter
``d`` pinches at ``t = d^2 / 8``, under velocity ``H n`` with ``H = 1 / r``, so
within the study's ``40 x 0.1 h^2 = 4 h^2`` when ``d < 2 sqrt(8) h``), and the
scheme's run of the study (40 steps of ``0.1 h^2``) on the mesh and on its Loop
refinement to the same final time: a real pinch keeps its time (the fraction
``t_failed / t_end`` stays), a mesh artefact moves with ``h^2`` (to a quarter).
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mcfbench.geometry import metrics  # noqa: E402
from mcfbench.geometry.committed_meshes import RAW_DIR, raw_manifest  # noqa: E402
from mcfbench.geometry.mesh_files import read_mesh  # noqa: E402
from mcfbench.geometry.subdivision import loop_step  # noqa: E402
from mcfbench.geometry.thickness import triangle_thickness  # noqa: E402
from mcfbench.running.driver import simulate  # noqa: E402
from mcfbench.running.remeshing import mesh_hook  # noqa: E402
from mcfbench.running.schemes import get_scheme  # noqa: E402
from mcfbench.running.solver import Solver  # noqa: E402

C, STEPS = 0.1, 40


def failure_fraction(scheme, V, F, t_end):
    """``(status, t_failed / t_end, steps done, steps)`` of the scheme's run to
    ``t_end`` with ``tau = C h^2`` on ``(V, F)``."""
    tau = C * metrics.mean_edge_length(V, F) ** 2
    steps = int(round(t_end / tau))
    traj = simulate(scheme.make(V, F, tau), steps, solver=Solver(method="jacobi-direct"),
                    remesh=mesh_hook(scheme, (V, F)))
    fraction = traj.failed_step * tau / t_end if traj.failed_step >= 0 else 1.0
    return traj.status, fraction, traj.steps_done, steps


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("meshes", nargs="*",
                        default=["double_torus_marching32", "quadknot", "kitten_decimated20"])
    parser.add_argument("--scheme", default="bgn+remesh")
    args = parser.parse_args()
    scheme = get_scheme(args.scheme)
    print(f"{'mesh':26} {'thickness/h q1 q5 q50':24} {'area < 5.66 h':>14} "
          f"level: status t_failed/t_end (steps)")
    for name in args.meshes:
        V, F, _ = read_mesh(str(RAW_DIR / raw_manifest()[name]["file"]))
        h = metrics.mean_edge_length(V, F)
        thick, area = triangle_thickness(V, F), metrics.triangle_areas(V, F)
        q = np.quantile(thick[np.isfinite(thick)], [0.01, 0.05, 0.5]) / h
        share = area[thick < 2 * np.sqrt(8) * h].sum() / area.sum()
        runs = []
        X, G = V, F
        for level in (0, 1):
            status, fraction, done, steps = failure_fraction(scheme, X, G, STEPS * C * h * h)
            runs.append(f"L{level}: {status} {fraction:.3f} ({done}/{steps})")
            X, G = loop_step(X, G)
        print(f"{name:26} {' '.join(f'{v:.2f}' for v in q):24} {share:14.3f} "
              f"{'; '.join(runs)}", flush=True)


if __name__ == "__main__":
    main()
