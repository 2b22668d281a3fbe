"""Angenent's torus, which shrinks self-similarly; it is unstable, so it is measured at t
= 0.25: distance to sqrt(1 - t) M_0 and area."""

from mcfbench.running.problem import Problem

ORDER = 6
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("angenent", "Angenent torus (self-shrinker)", "angenent_torus",
                  lambda level: {"n_major": 48 * 2 ** (level - 1), "n_minor": 24 * 2 ** (level - 1)},
                  levels=(1, 2, 3), tau_1=0.0125, t_final=0.25, metrics=("angenent",),
                  exact="M_t = sqrt(1 - t) M_0, extinct at t = 1",
                  kind="exact", main_metric="distance_error",
                  description="Angenent's torus, which shrinks self-similarly; it is unstable, so "
                              "it is measured at t = 0.25: distance to sqrt(1 - t) M_0 and area.")
