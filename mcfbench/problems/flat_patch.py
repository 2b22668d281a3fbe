"""An irregular Delaunay mesh of the unit disk with its boundary fixed: every vertex must
stay where it is."""

from mcfbench.running.problem import Problem

ORDER = 11
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("flat_patch", "flat patch stays flat and still", "flat_patch",
                  lambda level: {"level": int(level), "jitter": 0.3, "seed": 0},
                  levels=(1, 2, 3), tau_1=0.01, t_final=0.2, metrics=("still",),
                  exact="no motion: the flat disk is its own steady state",
                  kind="real_world", main_metric="max_displacement",
                  description="An irregular Delaunay mesh of the unit disk with its boundary fixed: "
                              "every vertex must stay where it is.")
