"""The tangential strategies compared from the matrix's tables
(mcfbench/studies/matrix/tangential.py, and the quality columns of the long table
it reads, mcfbench.studies.matrix.tables.quality_over_time): every number of the
section on a synthetic matrix whose answers are worked out by hand."""

import math

import numpy as np
import pytest

from mcfbench.studies.matrix import findings as matrix_findings
from mcfbench.studies.matrix import page as matrix_page
from mcfbench.studies.matrix import tables as matrix_tables
from mcfbench.studies.matrix.tangential import strategy_frame, tangential_section
from mcfbench.studies.matrix.verdicts import scheme_view

# scheme -> (CPU seconds per step, smallest angle and covolume ratio at t = 0, T/2, T)
RUNS = {"cotan": (1.0, [30.0, 20.0, 10.0], [1.2, 1.5, 2.0]),
        "ddfv-chord-carried": (3.0, [30.0, 25.0, 20.0], [1.2, 1.3, 1.4]),
        "bgn": (5.0, [30.0, 29.0, 28.0], [1.2, 1.25, 1.3])}
ERRORS = {("cotan", "sphere"): [1e-2, 2.5e-3], ("cotan", "real_nut"): [8e-2, 2e-2],
          ("ddfv-chord-carried", "sphere"): [1e-2, 5e-3],
          ("ddfv-chord-carried", "real_nut"): [7e-2, None],     # breaks down at level 1
          ("bgn", "sphere"): [8e-3, 2e-3], ("bgn", "real_nut"): [6e-2, 1e-2]}


def _record(scheme, problem, level, value):
    """A run record of 4 steps of tau 0.25 (t_final 1), its quality sampled at t = 0,
    0.5, 1; a run without a value broke down after one step (t = 0.25), where its
    smallest angle was 5 degrees and its covolume ratio 9."""
    per_step, angles, ratios = RUNS[scheme]
    broke = value is None
    steps = 1 if broke else 4
    series = ({"quality_t": [0.0, 0.25], "min_angle": [angles[0], 5.0],
               "covolume_ratio": [ratios[0], 9.0]} if broke else
              {"quality_t": [0.0, 0.5, 1.0], "min_angle": angles, "covolume_ratio": ratios})
    return {"scheme": scheme, "problem": problem, "level": level, "h": 0.5 / 2 ** level,
            "tau": 0.25, "N": 4, "steps_done": steps, "t_end": 0.25 * steps,
            "status": "inverted" if broke else "ok", "t_failed": 0.25 if broke else math.nan,
            "min_angle": min(series["min_angle"]), "max_flipped": 0.0,
            "t_min_barycentric": math.nan, "iterations": 1, "cpu_seconds": per_step * steps,
            "metric_names": ["area_error"], "area_error": math.nan if broke else value,
            "series": {"t": [], "t_min_barycentric": [], **series}}


@pytest.fixture(scope="module")
def matrix():
    records = [_record(s, p, level + (p == "sphere"), e) for (s, p), errors in ERRORS.items()
               for level, e in enumerate(errors)]
    table = matrix_tables.long_table(records)
    summary = scheme_view(matrix_tables.with_levels(
        matrix_tables.summary_table(table), table))
    return table, summary


def test_the_long_table_has_the_quality_at_start_middle_and_end(matrix):
    table, _ = matrix
    run = table[(table["scheme"] == "cotan") & (table["problem"] == "sphere")].iloc[-1]
    assert [run[f"min_angle_{w}"] for w in ("start", "middle", "end")] == [30.0, 20.0, 10.0]
    assert [run[f"covolume_ratio_{w}"] for w in ("start", "middle", "end")] == [1.2, 1.5, 2.0]
    broke = table[(table["scheme"] == "ddfv-chord-carried") & (table["problem"] == "real_nut")
                  & (table["level"] == 1)].iloc[0]
    # it never reached t = 0.5: no middle; its end is the state it broke down in
    assert math.isnan(broke["min_angle_middle"]) and broke["min_angle_end"] == 5.0
    assert broke["covolume_ratio_end"] == 9.0
    old = {k: v for k, v in _record("bgn", "sphere", 1, 1e-2).items() if k != "series"}
    assert all(math.isnan(v) for v in matrix_tables.quality_over_time(old).values())


def test_strategy_frame_on_numbers_worked_out_by_hand(matrix):
    table, summary = matrix
    strategy_of = {"cotan": "none", "ddfv-chord-carried": "none", "bgn": "bgn"}
    frame = strategy_frame(table, summary, strategy_of, real=["real_nut"]).set_index("strategy")
    none, bgn = frame.loc["none"], frame.loc["bgn"]
    assert none["schemes"] == ["cotan", "ddfv-chord-carried"] and bgn["schemes"] == ["bgn"]
    assert (none["finished"], none["series"], none["real_finished"], none["real_series"]) \
        == (2, 2, 1, 2)
    assert (bgn["finished"], bgn["series"], bgn["real_finished"], bgn["real_series"]) \
        == (1, 1, 1, 1)
    # finest errors over the smallest: sphere 2.5e-3, 5e-3 / 2e-3; real_nut 2e-2 / 1e-2
    assert none["accuracy"] == pytest.approx((1.25 * 2.5 * 2.0) ** (1 / 3))
    assert bgn["accuracy"] == pytest.approx(1.0)
    # finest runs of none: cotan 10, 10; ddfv-chord-carried 20 and the breakdown's 5
    assert [none[f"min_angle_{w}"] for w in ("start", "middle", "end")] == [30.0, 20.0, 10.0]
    assert none["covolume_ratio_end"] == pytest.approx(2.0)     # median of 2, 2, 1.4, 9
    assert none["covolume_ratio_middle"] == pytest.approx(1.5)  # 1.5, 1.5, 1.3 (no middle)
    assert [bgn[f"covolume_ratio_{w}"] for w in ("start", "middle", "end")] == [1.2, 1.25, 1.3]
    # CPU per step over cotan's: cotan 1 (4 runs), ddfv-chord-carried 3 (4 runs); bgn 5
    assert none["cost"] == pytest.approx(2.0) and bgn["cost"] == pytest.approx(5.0)


def test_every_sentence_of_the_section_comes_from_the_numbers(matrix):
    table, summary = matrix
    text = matrix_findings.matrix_findings(table, summary, mesh_problems=["real_nut"])
    section = text.split("## Tangential strategies")[1].split("\n## ")[0]
    assert "| none | cotan, ddfv-chord-carried | 2 of 2 | 1 of 2 | 1.84 | 30.0 → 20.0 → 10.0 " \
           "| 1.20 → 1.50 → 2.00 | 2 |" in section
    assert "| bgn | bgn | 1 of 1 | 1 of 1 | 1 | 30.0 → 29.0 → 28.0 | 1.20 → 1.25 → 1.30 | 5 |" \
        in section
    assert ("- Survival on the real meshes: the largest share of finished series (100%) for "
            "bgn (1 of 1), the smallest (50%) for none (1 of 2).") in section
    # on the refinement series both finished everything: no best and worst to name
    assert "Survival on the refinement series" not in section
    assert ("- Accuracy: bgn has the smallest finest-level errors (1 x the smallest, "
            "geometric mean), none the largest (1.84 x).") in section
    assert ("- Smallest angle at the end: bgn keeps the best (median 28.0 deg, from 30.0 at "
            "the start), none the worst (10.0 deg, from 30.0).") in section
    assert ("- Covolume ratio at the end: bgn keeps the best (median 1.3, from 1.2 at the "
            "start), none the worst (2, from 1.2).") in section
    assert ("- Cost: none is the cheapest per step (2 x cotan, median), bgn the most "
            "expensive (5 x).") in section
    assert "bgn: BGN's equidistribution" in section      # the registry's description
    # on the results page (the findings rendered): a table
    html = matrix_page.findings_html(section, ".")
    assert "<table>" in html and "<th>strategy</th>" in html
    assert '<td style="text-align: right;">1 of 2</td>' in html


def test_one_strategy_makes_no_section_and_no_cotan_no_cost(matrix):
    table, summary = matrix
    frame = strategy_frame(table, summary, {"cotan": "none", "bgn": "none"})
    assert len(frame) == 1 and tangential_section(frame) == []
    without = table[table["scheme"] != "cotan"], summary[summary["scheme"] != "cotan"]
    frame = strategy_frame(*without, {"ddfv-chord-carried": "none", "bgn": "bgn"})
    assert np.isnan(frame["cost"]).all() and not np.isnan(frame["accuracy"]).any()
    assert not any(line.startswith("- Cost") for line in tangential_section(frame))
