"""Two spheres joined by a thin neck: the volume at t = 0.08 and the time a run stops at
the pinch against the axisymmetric reference; past the pinch, the bulbs' volume and
extinction time (the reference continued through the pinch,
:mod:`mcfbench.geometry.meridian_surgery`; ``python benchmarks/axisymmetric_references.py
--problems dumbbell_after_pinch`` remakes them: cut at neck radii 0.01, 0.005, 0.0025,
meshes of 1 601-12 801 nodes; the error bars are Richardson's over the meshes plus the
change from the cut at 0.005, 8e-11 for the time and 1.5e-9 for the volumes)."""

from mcfbench.running.problem import Problem

ORDER = 5
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("dumbbell", "dumbbell pinch-off", "dumbbell",
                  lambda level: {"level": int(level)},
                  levels=(1, 2, 3), tau_1=0.004, t_final=0.2, metrics=("reference_volume", "shape",
                                                                       "bulb_volume"),
                  exact="axisymmetric reference: the neck pinches at t = 0.0905263, the bulbs "
                        "vanish at t = 0.2553923",
                  reference={"pinch_time": 0.0905263, "volume_time": 0.08, "volume": 4.93560212849,
                             "extinction_time": 0.2553922616, "extinction_time_accuracy": 8e-11,
                             "bulb_volume_times": (0.12, 0.16, 0.2),
                             "bulb_volume": (1.671384282, 0.9879185622, 0.4370147436),
                             "bulb_volume_accuracy": 1.6e-9},
                  kind="reference", main_metric="volume_error",
                  description="Two spheres joined by a thin neck: the volume at t = 0.08 and the time "
                              "a run stops at the pinch against the axisymmetric reference.")
