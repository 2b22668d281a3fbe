"""The reference numbers of the rotationally symmetric problems, as the problem
registry holds them (``mcfbench/running/problems.py``, field ``reference``).

    python benchmarks/axisymmetric_references.py            # full run, about 10 min
    python benchmarks/axisymmetric_references.py --quick    # coarser, about 1 min
    python benchmarks/axisymmetric_references.py --problems dumbbell_after_pinch

Prints the table of :func:`mcfbench.geometry.axisymmetric_references.reference_numbers`
(value and error estimate of every quantity) and, for the problems of the
registry that carry reference values, the registry's value next to the
recomputed one.
"""

import argparse
import os

os.environ.setdefault("OMP_NUM_THREADS", "1")   # multithreaded BLAS slows the banded solves

from mcfbench.geometry.axisymmetric_references import (  # noqa: E402
    format_cut_table,
    format_reference_table,
    reference_numbers,
)
from mcfbench.running.problems import PROBLEMS  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--problems", nargs="+", default=None,
                        help="a subset of reference_numbers' problems")
    args = parser.parse_args(argv)
    options = {} if args.problems is None else {"problems": tuple(args.problems)}
    ref = reference_numbers(quick=args.quick, **options)
    print(format_reference_table(ref))
    if "dumbbell_after_pinch" in ref:
        print(format_cut_table(ref["dumbbell_after_pinch"]))
    for name, problem in PROBLEMS.items():
        if not problem.reference or name not in ref:
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
