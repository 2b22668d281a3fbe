"""A torus of radii 2 and 0.5: its volume at t = 0.1 and the time a run stops at the
pinch against the axisymmetric reference."""

from mcfbench.running.problem import Problem

ORDER = 4
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("torus", "torus (2, 0.5) pinching", "torus",
                  lambda level: {"R": 2.0, "r": 0.5, "n_major": 32 * 2 ** (level - 1),
                                 "n_minor": 8 * 2 ** (level - 1)},
                  levels=(1, 2, 3), tau_1=0.004, t_final=0.2, metrics=("reference_volume", "shape"),
                  exact="axisymmetric reference: the tube pinches at t = 0.127111",
                  reference={"pinch_time": 0.127110542534, "volume_time": 0.1,
                             "volume": 2.07716576503},
                  kind="reference", main_metric="volume_error",
                  description="A torus of radii 2 and 0.5: its volume at t = 0.1 and the time a run "
                              "stops at the pinch against the axisymmetric reference.")
