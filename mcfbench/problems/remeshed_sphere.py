"""Random points on the unit sphere triangulated by their convex hull (slivers, valences
3 to 10)."""

from mcfbench.running.problem import Problem

ORDER = 9
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("remeshed_sphere", "sphere, random convex-hull mesh", "remeshed_sphere",
                  lambda level: {"n_points": 10 * 4 ** int(level) + 2, "seed": 0},
                  levels=(1, 2, 3, 4), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
                  exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
                  kind="real_world", main_metric="l2_error",
                  description="Random points on the unit sphere triangulated by their convex hull "
                              "(slivers, valences 3 to 10).")
