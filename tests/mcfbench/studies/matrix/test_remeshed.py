"""Each scheme beside its remeshed variant (mcfbench/studies/matrix/remeshed.py): every
number of the findings' section on a synthetic matrix worked out by hand."""

import math

import numpy as np
import pytest

from mcfbench.studies.matrix import findings as matrix_findings
from mcfbench.studies.matrix import tables as matrix_tables
from mcfbench.studies.matrix.plan import picture_specs, plan, planned_specs, runs_on
from mcfbench.studies.matrix.remeshed import (
    remeshed_pairs,
    remeshing_frame,
    remeshing_section,
)
from mcfbench.studies.matrix.verdicts import scheme_view

# (scheme, problem) -> error per level (None: broke down); sphere levels 1-2, real_nut 0-1
ERRORS = {("cotan", "sphere"): [1e-2, 2.5e-3], ("cotan+remesh", "sphere"): [1e-2, 5e-3],
          ("cotan", "real_nut"): [8e-2, 2e-2], ("cotan+remesh", "real_nut"): [4e-2, None],
          ("bgn", "sphere"): [8e-3, 2e-3], ("bgn", "real_nut"): [6e-2, 1e-2]}
# CPU seconds per step (4 steps a finished run, 1 a broken one)
PER_STEP = {"cotan": 1.0, "cotan+remesh": 3.0, "bgn": 5.0}


def _record(scheme, problem, level, value):
    broke = value is None
    steps = 1 if broke else 4
    return {"scheme": scheme, "problem": problem, "level": level, "h": 0.5 / 2 ** level,
            "tau": 0.25, "N": 4, "steps_done": steps, "t_end": 0.25 * steps,
            "status": "inverted" if broke else "ok", "t_failed": 0.25 if broke else math.nan,
            "min_angle": 20.0, "max_flipped": 0.0, "t_min_barycentric": math.nan,
            "iterations": 1, "cpu_seconds": PER_STEP[scheme] * steps,
            "metric_names": ["area_error"], "area_error": math.nan if broke else value,
            "series": {}}


@pytest.fixture(scope="module")
def matrix():
    records = [_record(s, p, level + (p == "sphere"), e) for (s, p), errors in ERRORS.items()
               for level, e in enumerate(errors)]
    table = matrix_tables.long_table(records)
    summary = scheme_view(matrix_tables.with_levels(
        matrix_tables.summary_table(table), table))
    return table, summary


def test_pairs_are_the_schemes_whose_remeshed_variant_ran_too():
    assert remeshed_pairs(["cotan", "bgn", "cotan+remesh"]) == [("cotan", "cotan+remesh")]
    assert remeshed_pairs(["cotan@bdf2", "cotan@bdf2+remesh", "cotan"]) == [
        ("cotan@bdf2", "cotan@bdf2+remesh")]
    assert remeshed_pairs(["cotan+remesh"]) == []


def test_the_plan_names_the_remeshed_variants_as_the_pairs_find_them():
    names = plan({"schemes": ["cotan", "bgn"], "with_remeshing": ["bgn", "mdr"],
                  "with_integrators": {}})["schemes"]
    assert names == ["cotan", "bgn", "bgn+remesh"]          # mdr is not run: nor remeshed
    assert remeshed_pairs(names) == [("bgn", "bgn+remesh")]


def test_no_remeshed_variant_where_every_run_already_takes_a_mesh_strategy():
    """On the dumbbell through its pinch every scheme runs as NAME+surgery (remeshing
    included): NAME+remesh is not run there, its scheme's run is."""
    chosen = plan({"select": {"schemes": ["cotan", "cotan+remesh"],
                              "problems": {"dumbbell_through_pinch": [1], "sphere": [1]}}})
    specs = planned_specs(chosen)
    assert sorted(specs) == [("dumbbell_through_pinch", "cotan", 1), ("sphere", "cotan", 1),
                             ("sphere", "cotan+remesh", 1)]
    assert specs[("dumbbell_through_pinch", "cotan", 1)].scheme == "cotan+surgery"
    assert sorted(picture_specs(chosen)) == [("dumbbell_through_pinch", "cotan"),
                                             ("sphere", "cotan"), ("sphere", "cotan+remesh")]
    assert runs_on("cotan+surgery", "dumbbell_through_pinch")
    assert not runs_on("cotan+remesh", "dumbbell_through_pinch")


def test_frame_on_numbers_worked_out_by_hand(matrix):
    table, summary = matrix
    frame = remeshing_frame(table, summary, [("cotan", "cotan+remesh")]).set_index("problem")
    assert list(frame.index) == ["sphere", "real_nut"]
    sphere, nut = frame.loc["sphere"], frame.loc["real_nut"]
    # sphere: both finish; level 2 compared, 5e-3 / 2.5e-3
    assert (sphere["error_level"], sphere["error_without"], sphere["error_with"]) \
        == (2, 2.5e-3, 5e-3)
    assert sphere["error_ratio"] == pytest.approx(2.0)
    assert (sphere["finished_without"], sphere["finished_with"], sphere["runs"]) == (2, 2, 2)
    # CPU over both levels: 4 + 4 steps at 1 s, at 3 s
    assert (sphere["cpu_without"], sphere["cpu_with"], sphere["cpu_ratio"]) == (8.0, 24.0, 3.0)
    assert sphere["without"].startswith("EOC 2.00; 2.500e-03 (L2)")
    assert sphere["with"].startswith("EOC 1.00; 5.000e-03 (L2)")
    # real_nut: the remeshed run breaks down at level 1: level 0 is compared, 4e-2 / 8e-2
    assert (nut["error_level"], nut["error_ratio"]) == (0, pytest.approx(0.5))
    assert (nut["finished_without"], nut["finished_with"]) == (2, 1)
    assert (nut["cpu_without"], nut["cpu_with"]) == (8.0, 15.0)      # 4 + 4; 12 + 3
    assert "inverted at t = 0.25 (level 1)" in nut["with"]


def test_no_common_finished_level_gives_no_ratio(matrix):
    table, summary = matrix
    broken = table.copy()
    broken.loc[(broken["scheme"] == "cotan") & (broken["problem"] == "real_nut")
               & (broken["level"] == 0), "status"] = "inverted"
    frame = remeshing_frame(broken, summary, [("cotan", "cotan+remesh")]).set_index("problem")
    assert np.isnan(frame.loc["real_nut", "error_level"])
    assert np.isnan(frame.loc["real_nut", "error_ratio"])


def test_a_run_the_robust_solver_finishes_counts_with_its_value_as_in_the_verdicts():
    records = [_record(s, "sphere", level, e) for s in ("cotan", "cotan+remesh")
               for level, e in ((1, 1e-2), (2, 2.5e-3))]
    records[-1].update(status="solver_failed", t_failed=0.5, area_error=math.nan,
                       robust_status="ok", robust_metrics={"area_error": 4e-3})
    table = matrix_tables.long_table(records)
    summary = scheme_view(matrix_tables.with_levels(matrix_tables.summary_table(table), table))
    (row,) = remeshing_frame(table, summary, [("cotan", "cotan+remesh")]).to_dict("records")
    assert (row["error_level"], row["finished_with"], row["error_with"]) == (2, 2, 4e-3)
    assert row["error_ratio"] == pytest.approx(1.6)             # 4e-3 / 2.5e-3


def test_every_number_of_the_section_comes_from_the_frame(matrix):
    table, summary = matrix
    frame = remeshing_frame(table, summary, [("cotan", "cotan+remesh")])
    text = "\n".join(remeshing_section(frame))
    # ratios 2.0 and 0.5: one smaller, one larger, geometric mean 1; CPU 16 s against 39 s
    assert ("- **cotan** against **cotan+remesh** on 2 problem(s): the error with remeshing "
            "is smaller on 1, larger on 1 of the 2 compared (geometric mean ratio 1); "
            "finished runs 4 of 4 without, 3 with; CPU 16 s without, 39 s with "
            "(2.44 x).") in text
    assert "| sphere (area_error) | cotan |" in text and "| L2 | 2 | 3 |" in text
    assert "| L0 | 0.5 | 1.88 |" in text
    assert remeshing_section(frame.iloc[:0]) == []


def test_the_findings_show_the_pair_and_keep_remeshing_out_of_the_tangential_strategies(matrix):
    table, summary = matrix
    text = matrix_findings.matrix_findings(table, summary, mesh_problems=["real_nut"])
    assert "## With remeshing against without" in text
    section = text.split("## With remeshing against without")[1].split("\n## ")[0]
    assert "**bgn**" not in section                  # no bgn+remesh ran
    assert text.index("## On the real meshes") < text.index("## With remeshing")
    tangential = text.split("## Tangential strategies")[1]
    assert "cotan+remesh" not in tangential and "cotan" in tangential
