"""A UV sphere with long thin triangles (length/width 4 at the equator) and poles of high
valence."""

from mcfbench.running.problem import Problem

ORDER = 10
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("anisotropic_sphere", "sphere, anisotropic UV mesh", "anisotropic_sphere",
                  lambda level: {"level": int(level), "stretch": 4.0},
                  levels=(1, 2, 3, 4), tau_1=0.04, t_final=0.08, metrics=("sphere_l2",),
                  exact="r(t) = sqrt(R^2 - 4t)", t_max=0.25,
                  kind="real_world", main_metric="l2_error",
                  description="A UV sphere with long thin triangles (length/width 4 at the "
                              "equator) and poles of high valence.")
