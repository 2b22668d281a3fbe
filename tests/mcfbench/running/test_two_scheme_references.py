"""The reference machinery (mcfbench.running.two_scheme_references) on a case with a
known answer, the shrinking sphere r(t)^2 = 1 - 4t: its reference area and
volume agree with the exact ones within the stated accuracy, and so does its
reference surface's distance to the exact sphere; and the singularity rule
on synthetic runs."""

import math

import numpy as np
import pytest

from mcfbench.geometry.metrics import mean_edge_length
from mcfbench.geometry.spheres import icosphere
from mcfbench.geometry.surface_distance import mean_surface_distance
from mcfbench.running.problems import PROBLEMS
from mcfbench.running.two_scheme_references import (
    ACCURACY,
    distance_answers,
    first_singularity,
    reference_answers,
    reference_runs,
)


@pytest.fixture(scope="module")
def sphere_answers():
    problem = PROBLEMS["sphere"]
    h = mean_edge_length(*problem.mesh(2))
    tau_0 = 0.1 * h ** 2
    runs = reference_runs(problem, {"cotan": (2, 3, 4), "bgn": (2, 3)}, tau_0, 4)
    return tau_0, reference_answers(runs, tau_0, 4), runs


def test_sphere_reference_is_within_its_stated_accuracy(sphere_answers):
    tau_0, ref, _ = sphere_answers
    assert ref["steps"] == 4 and ref["singularity"]["time"] is None
    t = tau_0 * np.asarray(ref["checkpoints"])
    exact = {"area": 4 * np.pi * (1 - 4 * t), "volume": 4 / 3 * np.pi * (1 - 4 * t) ** 1.5}
    for q in ("area", "volume"):
        error = np.abs(np.asarray(ref[q]) - exact[q])
        accuracy = np.asarray(ref[f"{q}_accuracy"])
        assert np.all(error <= accuracy), (q, error, accuracy)
        assert np.all(accuracy < 0.005 * exact[q])       # and the accuracy is informative
        assert ref[f"{q}_disagree"] == []
    cotan = ref["orders"]["cotan"]["volume"]["observed"]
    assert len(cotan) == 1 and 1.5 < cotan[0] < 2.5        # O(h^2 + tau), tau ~ h^2


def test_sphere_reference_surface_is_within_its_stated_distance_accuracy(sphere_answers):
    """The finest cotangent run at t_final against the exact sphere
    r^2 = 1 - 4 t_final (a finer icosphere of that radius)."""
    tau_0, ref, runs = sphere_answers
    answers, (surface, faces) = distance_answers(runs, ref, tau_0)
    radius = np.sqrt(1 - 4 * ref["steps"] * tau_0)
    assert answers["distance_reference"] == {"scheme": "cotan", "level": 4, "checkpoint": 4,
                                             "vertices": len(surface)}
    assert answers["length_scale"] == pytest.approx(np.sqrt(4 * np.pi) * radius, rel=1e-3)
    finest = next(r for r in runs if (r["scheme"], r["level"]) == ("cotan", 4))["surface"]
    np.testing.assert_array_equal(faces, finest["faces"])
    np.testing.assert_array_equal(surface, finest["positions"][4])
    error = mean_surface_distance(surface, faces, *icosphere(6, radius)) / answers["length_scale"]
    accuracy = answers["distance_accuracy"]
    assert accuracy == max(answers["distance_level_difference"],
                           answers["distance_scheme_difference"])
    assert error <= accuracy < 1e-3, (error, accuracy)


def test_distance_needs_a_checkpoint_and_two_levels_reaching_it(sphere_answers):
    tau_0, ref, runs = sphere_answers
    with pytest.raises(ValueError, match="no checkpoint"):
        distance_answers(runs, {**ref, "steps": 0}, tau_0)
    with pytest.raises(ValueError, match="two finest runs"):
        distance_answers([r for r in runs if r["level"] == 2], ref, tau_0)


def _run(scheme, level, status, t_end, tau_0=0.1, steps=10, spread=lambda j: 1e-3):
    """Values ``1 - 0.01 j + spread(j) 0.5^level``: first order in h, the levels
    ``spread(j)`` apart at checkpoint ``j``."""
    reached = min(steps, math.floor(t_end / tau_0 + 1e-9))
    values = [1.0 + spread(j) * 0.5 ** level - 0.01 * j if j <= reached else math.nan
              for j in range(steps + 1)]
    return {"scheme": scheme, "level": level, "status": status, "t_end": t_end,
            "area": values, "volume": values}


def test_runs_that_stop_together_are_the_singularity_and_t_final_is_before_it():
    runs = [_run("cotan", 0, "ok", 1.0), _run("cotan", 1, "inverted", 0.74),
            _run("cotan", 2, "inverted", 0.71), _run("bgn", 0, "degenerated", 0.66),
            _run("bgn", 1, "inverted", 0.69)]
    sing = first_singularity(runs, 0.1, 10)
    assert sing["time"] == pytest.approx((0.71 + 0.69) / 2) and sing["breakdowns"] == []
    ref = reference_answers(runs, 0.1, 10)
    assert ref["steps"] == 6 and ref["checkpoints"] == [1, 2, 3, 4, 5, 6]


def test_runs_that_stop_apart_are_breakdowns_not_the_singularity():
    runs = [_run("cotan", 0, "inverted", 0.2), _run("cotan", 1, "inverted", 0.15),
            _run("bgn", 0, "ok", 1.0), _run("bgn", 1, "ok", 1.0)]
    sing = first_singularity(runs, 0.1, 10)
    assert sing["time"] is None and sing["searched_to"] == pytest.approx(1.0)
    assert [(b["scheme"], b["level"]) for b in sing["breakdowns"]] == [("cotan", 0), ("cotan", 1)]
    ref = reference_answers(runs, 0.1, 10)     # the final time is the flow's, not cotan's
    assert ref["steps"] == 10
    assert ref["area_schemes"] == [["bgn", "cotan"]] + [["bgn"]] * 9
    assert ref["orders"]["cotan"]["area"]["checkpoint"] == 1


def test_final_time_stops_before_the_first_checkpoint_known_worse_than_the_accuracy():
    def spread(j):          # the levels part from checkpoint 7 on (a coarse mesh shrinking fast)
        return 1e-3 if j < 7 else 0.2
    runs = [_run(s, lv, "ok", 1.0, spread=spread) for s, lv in
            (("cotan", 0), ("cotan", 1), ("cotan", 2), ("bgn", 0), ("bgn", 1))]
    ref = reference_answers(runs, 0.1, 10)
    assert ref["steps"] == 6 and ref["singularity"]["time"] is None
    accuracy = np.asarray(ref["area_accuracy"]) / np.abs(ref["area"])
    assert np.all(accuracy <= ACCURACY) and accuracy.max() > 0
    # Richardson on cotan's three levels (order 1): the exact limit 1 - 0.01 j
    assert ref["area"] == pytest.approx([1 - 0.01 * j for j in range(1, 7)], rel=1e-12)
    assert reference_answers([_run(s, lv, "ok", 1.0) for s, lv in
                              (("cotan", 0), ("cotan", 1), ("bgn", 0), ("bgn", 1))],
                             0.1, 10)["steps"] == 10
