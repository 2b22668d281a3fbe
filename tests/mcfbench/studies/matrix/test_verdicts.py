"""The verdicts of the matrix (mcfbench.studies.matrix.verdicts): the classes of a series
and the recommendation's data, from synthetic long tables with known numbers."""

import math

import pandas as pd
import pytest

from mcfbench.studies.matrix import tables
from mcfbench.studies.matrix.verdicts import classify, recommend, scheme_view


def _summary(errors, problem="sphere", accuracy=None, metric="l2_error"):
    """The scheme view of the summary of ``{scheme: [error per level 1, 2, ...]}``."""
    rows = []
    for scheme, values in errors.items():
        for k, v in enumerate(values, start=1):
            rows.append({"scheme": scheme, "problem": problem, "level": k, "h": 0.5 / 2 ** k,
                         "tau": 0.01, "steps": 10, "steps_done": 10, "metric": metric,
                         "main": True, "value": v, "eoc": math.nan,
                         "eoc_below_accuracy": False,
                         "reference_accuracy": (accuracy or {}).get(problem, math.nan),
                         "status": "ok", "t_failed": math.nan, "min_angle": 30.0,
                         "max_flipped": 0.0, "t_min_barycentric": math.nan,
                         "iterations": 1, "cpu_seconds": 0.1, "robust_status": "",
                         "robust_value": math.nan, "robust_t_failed": math.nan})
    table = tables.add_eoc(pd.DataFrame(rows))
    return scheme_view(tables.with_levels(tables.summary_table(table), table))


def test_an_eoc_into_the_reference_s_accuracy_is_its_own_class_and_meets_the_order_rule():
    errors = {"a": [4e-2, 1e-2, 2.5e-3], "b": [3.2e-3, 8e-4, 8e-4], "d": [1.8e-2, 3e-3, 5e-4]}
    summary = _summary(errors, accuracy={"sphere": 1e-3})
    classes = {r["scheme"]: classify(r) for _, r in summary.iterrows()}
    assert classes == {"a": "order2", "b": "below_accuracy", "d": "below_accuracy"}
    rec = recommend(summary, ["sphere"], list(errors))
    assert rec["ranked"] == ["d", "b", "a"] and rec["why_not"] == {}
    # finest errors 2.5e-3, 8e-4, 5e-4 over the smallest, 5e-4
    assert rec["score"] == pytest.approx({"a": 5.0, "b": 1.6, "d": 1.0})
    assert rec["winners"] == {"sphere": "d"}
    (exception,) = rec["exceptions"]
    assert exception["class"] == "below_accuracy" and exception["winner"] == "d"
    assert math.isnan(exception["eoc"]) and exception["ratio"] == 1.0


def test_without_the_accuracy_the_same_errors_leave_d_out_and_b_wins():
    errors = {"a": [4e-2, 1e-2, 2.5e-3], "b": [3.2e-3, 8e-4, 8e-4], "d": [1.8e-2, 3e-3, 5e-4]}
    summary = _summary(errors)
    rec = recommend(summary, ["sphere"], list(errors))
    assert rec["why_not"] == {"d": ["EOC 2.58 on sphere"]}
    assert rec["ranked"] == ["b", "a"] and rec["tied"] == []
    # b stops at 8e-4 (EOC 0), below a's order-2 error 2.5e-3: a floor, not held against it
    (exception,) = rec["exceptions"]
    assert exception["eoc"] == 0.0 and "a floor" in exception["note"]


def test_a_breakdown_on_a_real_world_like_mesh_leaves_a_scheme_out_and_is_counted():
    good = _summary({"a": [1e-2, 2.5e-3, 6.25e-4], "b": [2e-2, 5e-3, 1.25e-3]})
    mesh = _summary({"a": [1e-2, 2.5e-3], "b": [1e-2, 2.5e-3]}, problem="blobby",
                    metric="volume")
    mesh.loc[mesh["scheme"] == "b", ["runs_ok", "status"]] = [1, "inverted"]
    summary = pd.concat([good, mesh], ignore_index=True)
    rec = recommend(summary, ["sphere", "blobby"], ["a", "b"], mesh_problems=["blobby"])
    assert rec["exact"] == ["sphere"] and rec["singular"] == []
    assert rec["breakdowns"] == {"a": [], "b": ["blobby"]}
    assert rec["why_not"] == {"b": ["broke down on blobby"]} and rec["ranked"] == ["a"]
    assert rec["exceptions"] == []       # a: order 2 and the most accurate
