"""The unit hemisphere with its equator fixed flows to the disk; the decay rate of its
height between t = 1 and 1.5 against the first Dirichlet eigenvalue of the disk."""

from mcfbench.running.problem import Problem

ORDER = 3
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("hemisphere", "hemisphere to flat disk", "hemisphere",
                  lambda level: {"rings": 5 * 2 ** (level - 1), "radius": 1.0},
                  levels=(1, 2, 3, 4), tau_1=0.01, t_final=2.0, metrics=("decay", "height"),
                  steady_speed=1e-6,
                  exact="the flat disk z = 0, approached at the rate j01^2 / R^2 = 5.78319",
                  kind="exact", main_metric="decay_rate_error",
                  description="The unit hemisphere with its equator fixed flows to the disk; the "
                              "decay rate of its height between t = 1 and 1.5 against the first "
                              "Dirichlet eigenvalue of the disk.")
