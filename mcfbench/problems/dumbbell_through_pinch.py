"""The dumbbell through its pinch to both bulbs' extinction (issue #45): every scheme
run as ``NAME+surgery`` (the neck cut once its radius is below half an edge,
:mod:`mcfbench.running.surgery`), to the flow's end; measured against the axisymmetric
reference continued through the pinch (:mod:`mcfbench.geometry.meridian_surgery`, the
numbers and their error bars of :mod:`mcfbench.problems.dumbbell`): the bulbs'
extinction time (``extinction_time_error``, relative and signed: the last bulb's
extinction time, extrapolated by :mod:`mcfbench.geometry.collapse`, over the
reference's 0.2553922616 +- 8e-11, minus 1), the pinch time (``pinch_time_error``,
the cut's time plus ``r^2 / 2``) and one bulb's volume after the pinch
(``bulb_volume_error``: the largest relative error of the bulbs' volumes at t = 0.12,
0.16 and 0.2 against the reference's, +- 1.6e-9)."""

from mcfbench.problems.dumbbell import PROBLEM as DUMBBELL
from mcfbench.running.problem import Problem

ORDER = 5
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`): the
dumbbell's, after it by name."""

PROBLEM = Problem("dumbbell_through_pinch", "dumbbell through its pinch (NAME+surgery)",
                  "dumbbell", DUMBBELL.params, levels=(1, 2, 3), tau_1=0.004, t_final=0.3,
                  metrics=("bulb_volume",), to_extinction=True, mesh_strategy="surgery",
                  exact="axisymmetric reference continued through the pinch: the neck "
                        "pinches at t = 0.0905263, the bulbs vanish at t = 0.2553923",
                  reference={k: DUMBBELL.reference[k] for k in (
                      "pinch_time", "extinction_time", "extinction_time_accuracy",
                      "bulb_volume_times", "bulb_volume", "bulb_volume_accuracy")},
                  kind="reference", main_metric="extinction_time_error",
                  description="The dumbbell run by every scheme as NAME+surgery (its neck cut "
                              "and capped below half an edge) to both bulbs' extinction: the "
                              "extinction time, the pinch time and the bulbs' volume after the "
                              "pinch against the axisymmetric reference continued through it.")
