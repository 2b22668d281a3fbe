"""Two spheres joined by a thin neck: the volume at t = 0.08 and the time a run stops at
the pinch against the axisymmetric reference."""

from mcfbench.running.problem import Problem

ORDER = 5
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("dumbbell", "dumbbell pinch-off", "dumbbell",
                  lambda level: {"level": int(level)},
                  levels=(1, 2, 3), tau_1=0.004, t_final=0.2, metrics=("reference_volume", "shape"),
                  exact="axisymmetric reference: the neck pinches at t = 0.0905263",
                  reference={"pinch_time": 0.0905263, "volume_time": 0.08, "volume": 4.93560212849},
                  kind="reference", main_metric="volume_error",
                  description="Two spheres joined by a thin neck: the volume at t = 0.08 and the time "
                              "a run stops at the pinch against the axisymmetric reference.")
