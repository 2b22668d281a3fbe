"""The icosphere with vertices moved at random along the sphere: irregular valences and
angles, exact solution known."""

from mcfbench.running.problem import Problem

ORDER = 8
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("perturbed_sphere", "sphere, randomly perturbed mesh", "perturbed_sphere",
                  lambda level: {"level": int(level), "amplitude": 0.25, "seed": 0},
                  levels=(1, 2, 3, 4), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
                  exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
                  kind="real_world", main_metric="l2_error",
                  description="The icosphere with vertices moved at random along the sphere: "
                              "irregular valences and angles, exact solution known.")
