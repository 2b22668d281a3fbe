"""The reference numbers of the rotationally symmetric problems, as the problem
registry holds them (``mcfbench/running/problems.py``, field ``reference``).

    python benchmarks/axisymmetric_references.py            # full run, about 90 s
    python benchmarks/axisymmetric_references.py --quick    # coarser, about 15 s

Prints the table of :func:`mcfbench.geometry.axisymmetric_references.reference_numbers`
(value and error estimate of every quantity) and, for the problems of the
registry that carry reference values, the registry's value next to the
recomputed one.
"""

import argparse
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")   # multithreaded BLAS slows the banded solves

from mcfbench.geometry.axisymmetric_references import (  # noqa: E402
    format_reference_table,
    reference_numbers,
)
from mcfbench.running.problems import PROBLEMS  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    ref = reference_numbers(quick=args.quick)
    print(format_reference_table(ref))
    for name, problem in PROBLEMS.items():
        if not problem.reference:
            continue
        computed = ref[name]
        k = list(computed["times"]).index(problem.reference["volume_time"])
        print(f"{name}: pinch time registry {problem.reference['pinch_time']:.12g}, computed "
              f"{computed['pinch_time'][0]:.12g} +- {computed['pinch_time'][1]:.1e}; volume at "
              f"t = {problem.reference['volume_time']:g} registry "
              f"{problem.reference['volume']:.12g}, computed {computed['volume'][0][k]:.12g} "
              f"+- {computed['volume'][1][k]:.1e}")


if __name__ == "__main__":
    main()
