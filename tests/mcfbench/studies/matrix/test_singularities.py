"""The findings' section "Through singularities" from a long table (issue #45)."""

import numpy as np
import pandas as pd
import pytest

from mcfbench.studies.matrix.singularities import (singular_problems, singularity_frame,
                                                   singularity_section)


def _rows(scheme, problem, statuses, values, metric="extinction_time_error", robust=()):
    robust = dict(robust)
    return [{"scheme": scheme, "problem": problem, "level": lv, "metric": metric,
             "value": v, "status": st, "robust_status": robust.get(lv, ("", np.nan))[0],
             "robust_value": robust.get(lv, ("", np.nan))[1]}
            for lv, (st, v) in enumerate(zip(statuses, values), start=1)]


@pytest.fixture
def table():
    rows = (_rows("cotan", "pinch", ["extinct"] * 3, [0.044, 0.0156, 0.0049])
            + _rows("cotan", "pinch", ["extinct"] * 3, [0.137, 0.036, 0.0091],
                    metric="bulb_volume_error")
            + _rows("ddfv", "pinch", ["t_escaped"] * 3, [np.nan] * 3)
            + _rows("ddfv", "pinch", ["t_escaped"] * 3, [np.nan] * 3, metric="bulb_volume_error")
            # a solver failure at level 2 the robust re-run takes to the extinction
            + _rows("chord", "pinch", ["extinct", "solver_failed", "inverted"],
                    [0.044, np.nan, np.nan], robust={2: ("extinct", 0.011)})
            + _rows("chord", "pinch", ["extinct", "solver_failed", "inverted"],
                    [0.1, np.nan, np.nan], metric="bulb_volume_error",
                    robust={2: ("extinct", 0.025)})
            + _rows("cotan", "sphere", ["ok"] * 3, [1e-2, 2.5e-3, 6.25e-4], metric="l2_error"))
    return pd.DataFrame(rows)


def test_the_problems_are_those_with_an_extinct_run(table):
    assert singular_problems(table) == ["pinch"]
    assert singularity_section(table[table["problem"] == "sphere"]) == []


def test_per_scheme_the_finest_level_reached_its_errors_and_orders(table):
    frame = singularity_frame(table, "pinch").set_index("scheme")
    assert list(frame["through"]) == [True, False, False]
    assert frame.loc["cotan", "finest"] == 3 and np.isnan(frame.loc["ddfv", "finest"])
    assert frame.loc["cotan", "extinction_time_error"] == 0.0049
    assert frame.loc["cotan", "extinction_time_error_eoc"] == pytest.approx(np.log2(0.0156 / 0.0049))
    assert frame.loc["cotan", "bulb_volume_error_eoc"] == pytest.approx(np.log2(0.036 / 0.0091))
    # the robust re-run counts at level 2; level 3 broke down
    assert frame.loc["chord", "finest"] == 2
    assert frame.loc["chord", "extinction_time_error"] == 0.011
    assert frame.loc["chord", "statuses"] == "L1 extinct, L2 extinct, L3 inverted"
    assert "pinch_time_error" not in frame


def test_the_section_says_who_goes_through(table):
    text = "\n".join(singularity_section(table))
    assert "### pinch" in text and "1 of the 3 schemes go through at every level (cotan)" in text
    assert "ddfv (L1 t_escaped, L2 t_escaped, L3 t_escaped)" in text
    assert "| cotan | 3 | +0.0049 | 1.67 | +0.0091 | 1.98 |" in text


def test_a_summary_row_whose_runs_all_went_extinct_reads_extinct():
    """The summary's cell of a series that reached the flow's end at every level (status
    ``extinct``, no level failed) names it instead of a breakdown (it raised on the NaN
    level before)."""
    from mcfbench.studies.matrix.tables import breakdown_text

    assert breakdown_text("extinct", np.nan, np.nan) == "extinct"
    assert breakdown_text("t_escaped", 0.052, 3.0) == "t_escaped at t = 0.052 (level 3)"
