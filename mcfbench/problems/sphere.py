"""The unit icosphere of Section 3.1, tau = 0.04 / 4^(k-1), t_f = 0.08; the error (3.2)."""

from mcfbench.running.problem import Problem

ORDER = 1
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""


def _params(level):
    return {"level": int(level), "radius": 1.0}


PROBLEM = Problem("sphere", "shrinking sphere (Table 3.1)", "sphere", _params,
                  levels=(1, 2, 3, 4, 5), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
                  exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
                  kind="exact", main_metric="l2_error",
                  description="The unit icosphere of Section 3.1, tau = 0.04 / 4^(k-1), t_f = 0.08; "
                              "the error (3.2).")
