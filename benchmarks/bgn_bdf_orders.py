"""BGN with BDF-k in time (issue #47): the time order of ``bgn-bdf2``, ``bgn-bdf3`` (Jiang,
Su and Zhang's predictor surfaces, :mod:`baselines.bgn_bdf`) against the harness's
generic ``bgn@bdf2``, ``bgn@bdf3``, with the beyond study's time-study settings
(``beyond.time_study``: the fixed mesh, taus halved from 0.01, a reference at the
smallest tau / 8, BiCGStab at rtol 1e-12): the sphere's level 3 to t = 0.08 and the
catenoid's level 2 to t = 0.5 (taus from 0.02).

Printed per scheme and problem: the volume between each run's last surface and the
reference's (:func:`mcfbench.geometry.metrics.final_state_distance`, blind to BGN's
tangential motion) and its EOCs, the pointwise error's EOCs, every run's status (the
harness checks the area at every step, ``area_grew``), and ``start`` (``bgn-bdf3``:
``"equilibrium"``; ``--start`` runs another for comparison). A reference run that
breaks down is printed as such (``RuntimeError``'s message).

Usage::

    python benchmarks/bgn_bdf_orders.py [--schemes bgn-bdf3 bgn@bdf3] [--problems sphere]
    python benchmarks/bgn_bdf_orders.py --schemes bgn-bdf3 --start bgn
"""

import argparse

from mcfbench.running.run import time_convergence
from mcfbench.running.solver import Solver

SETTINGS = {"sphere": (3, 0.08, [0.01, 0.005, 0.0025, 0.00125, 0.000625]),
            "catenoid": (2, 0.5, [0.02, 0.01, 0.005, 0.0025])}
"""problem -> (level, t_final, taus)."""


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--schemes", nargs="+",
                        default=["bgn-bdf2", "bgn-bdf3", "bgn@bdf2", "bgn@bdf3"])
    parser.add_argument("--problems", nargs="+", default=list(SETTINGS))
    parser.add_argument("--start", help="bgn-bdf2/3's start (default: the registry's)")
    args = parser.parse_args()
    options = {"start": args.start} if args.start else {}
    for problem in args.problems:
        level, t_final, taus = SETTINGS[problem]
        for scheme in args.schemes:
            own = options if scheme.startswith("bgn-bdf") else {}
            title = f"{scheme} {own or ''} on {problem} level {level} to t = {t_final}"
            try:
                table = time_convergence(scheme, problem, level, taus, reference_factor=8,
                                         t_final=t_final, solver=Solver(rtol=1e-12), **own)
            except RuntimeError as err:
                print(f"{title}: {err}\n")
                continue
            print(title)
            print(table[["tau", "N", "volume_error", "volume_eoc", "eoc", "status"]]
                  .to_string(index=False, float_format=lambda v: f"{v:.3g}"), "\n")


if __name__ == "__main__":
    main()
