"""The matrix's plan of the dumbbell through its pinch (issue #45): every scheme run as
NAME+surgery and filed under NAME."""

import pytest

from mcfbench.running.problem import Problem
from mcfbench.running.problems import get_problem
from mcfbench.studies.matrix.plan import matrix_scheme, plan, planned_specs, run_scheme


def test_the_problem_runs_every_scheme_with_surgery_to_the_extinction():
    p = get_problem("dumbbell_through_pinch")
    assert p.mesh_strategy == "surgery" and p.to_extinction
    assert p.reference["extinction_time"] == get_problem("dumbbell").reference["extinction_time"]
    assert p.main_metric == "extinction_time_error"
    V, F = p.mesh(1)
    assert len(V) == 2546 and p.time_steps(p.tau(3)) == 1200        # t = 0.3 past 0.2554


def test_the_plan_runs_name_plus_surgery_and_files_it_under_name():
    assert run_scheme("cotan", "dumbbell_through_pinch") == "cotan+surgery"
    assert run_scheme("cotan@bdf2", "dumbbell_through_pinch") == "cotan@bdf2+surgery"
    assert run_scheme("cotan+surgery", "dumbbell_through_pinch") == "cotan+surgery"
    assert run_scheme("cotan", "dumbbell") == "cotan"
    assert matrix_scheme("cotan@bdf2+surgery", "dumbbell_through_pinch") == "cotan@bdf2"
    assert matrix_scheme("cotan+remesh", "dumbbell") == "cotan+remesh"
    specs = planned_specs(plan({"schemes": ["ddfv", "cotan"],
                                "problems": {"dumbbell": [1], "dumbbell_through_pinch": [1, 2]},
                                "select": {"problems": {"dumbbell": [1],
                                                        "dumbbell_through_pinch": [1, 2]}}}))
    assert {k: v.scheme for k, v in specs.items()} == {
        ("dumbbell", "ddfv", 1): "ddfv", ("dumbbell", "cotan", 1): "cotan",
        **{("dumbbell_through_pinch", s, lv): f"{s}+surgery" for s in ("ddfv", "cotan")
           for lv in (1, 2)}}


def test_a_problem_refuses_an_unknown_mesh_strategy():
    with pytest.raises(ValueError, match="unknown mesh strategy 'cut'"):
        Problem("x", "x", "sphere", lambda level: {}, levels=(1,), tau_1=0.1, t_final=0.1,
                metrics=(), mesh_strategy="cut")
