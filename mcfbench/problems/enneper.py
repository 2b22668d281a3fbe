"""Enneper's minimal surface over the parameter disk of radius 0.6, boundary fixed,
interior lifted by 0.1: by t = 1 it has relaxed to the minimal surface (the
application of the journal version). At R = 0.8 the relaxation is four times slower (R
= 1 is the limit of stability)."""

from mcfbench.running.problem import Problem

ORDER = 7
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("enneper", "Enneper patch relaxing to the minimal surface", "enneper_patch",
                  lambda level: {"level": int(level), "radius": 0.6, "lift": 0.1},
                  levels=(1, 2, 3), tau_1=0.02, t_final=1.0, metrics=("enneper",),
                  steady_speed=1e-6, exact="Enneper's surface, area (pi/3)((1 + R^2)^3 - 1)",
                  kind="exact", main_metric="height_error",
                  description="Enneper's minimal surface over the parameter disk of radius 0.6, "
                              "boundary fixed, interior lifted by 0.1: by t = 1 it has relaxed to "
                              "the minimal surface (the application of the journal version). At "
                              "R = 0.8 the relaxation is four times slower (R = 1 is the limit of "
                              "stability).")
