"""The study beyond Table 3.1 (workflow/rules/beyond.smk; mcfbench.studies.beyond, .tables,
.plots, .beyond_findings).

Runs that break down must end up as rows with their status, the time of
the breakdown, an empty L2 error and no EOC against them; the aggregation
is checked on small synthetic records, the config key ``beyond`` on its
schema and its checks across keys (scheme names against the registry). No
level-6 run here.
"""

import io
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from mcfbench.pipeline import Plans, mem_mb, runtime_minutes
from mcfbench.presentation.plots import beyond_figures, scaling_figure
from mcfbench.running.integrators import INTEGRATORS
from mcfbench.running.run import space_convergence
from mcfbench.running.schemes import SCHEMES
from mcfbench.storage.atomic import write_files
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.provenance import config_hash
from mcfbench.storage.records import RecordError, read_record, read_records
from mcfbench.studies.beyond.findings import beyond_findings
from mcfbench.studies.beyond.findings import findings as verdicts
from mcfbench.running.batch import compute, spec_of
from mcfbench.storage.run_store import record_path, store_settings
from mcfbench.studies.beyond.aggregate import time_records
from mcfbench.studies.beyond.plan import (
    TABLE_STUDIES,
    levels_of,
    scaling_fit_levels,
    scaling_levels,
    study_specs,
    used_schemes,
)
from mcfbench.studies.beyond.tables import (
    beyond_documents,
    beyond_tables,
    monitor_summary,
    scaling_documents,
    scaling_tables,
    space_table,
    time_order,
)
from mcfbench.studies.config import ConfigError
from mcfbench.studies.convergence.plan import problem_of, sphere_spec
from mcfbench.studies.convergence.tables import convergence_documents, eoc_column, level_table

REPO = Path(__file__).resolve().parents[4]
SCHEMAS = REPO / "workflow" / "schemas"
CONFIG = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
SETTINGS = {"t_final": 0.08, "tau_level_1": 0.04, "rtol": 1e-9}


# -- synthetic records ----------------------------------------------------------

def record(scheme, level, *, status="ok", l2=None, monitor=None, tau=None, t_final=0.08):
    """A run record as mcfbench.storage.records.read_record returns it (without the file)."""
    tau = 0.04 / 4 ** (level - 1) if tau is None else tau
    steps = round(t_final / tau)
    ok = status == "ok"
    ddfv = SCHEMES[scheme].family == "ddfv"
    if monitor is None:
        monitor = list(np.linspace(0.33, 0.3, steps + 1 if ok else 2))
    levels = len(monitor)
    return {
        "scheme": scheme, "problem": "sphere", "level": level,
        "nV": 10 * 4 ** level + (20 * 4 ** level if ddfv else 0), "nF": 10 * 4 ** level,
        "nT": 20 * 4 ** level if ddfv else 0, "h": 0.6 / 2 ** (level - 1), "tau": tau,
        "N": steps, "steps_done": levels - 1, "status": status,
        "message": "" if ok else f"{status} at step {levels} (t = {levels * tau:g}): ...",
        "t_failed": float("nan") if ok else levels * tau, "t_end": (levels - 1) * tau,
        "steady": False, "iterations": 5 * steps, "solver": "bicgstab",
        "cpu_seconds": 0.1 * level, "wall_seconds": 0.1 * level, "peak_rss_mb": 50.0 * level,
        "t_min_barycentric": float(np.min(monitor)) if ddfv else float("nan"),
        "min_angle": 0.5, "max_aspect": 2.0, "max_flipped": 0.0,
        "l2_error": (1.3e-2 / 4 ** (level - 1) if l2 is None else l2) if ok else float("nan"),
        "series": {"t": list(tau * np.arange(levels)),
                   "t_min_barycentric": list(monitor) if ddfv else [float("nan")] * levels},
        "settings": {"scheme": scheme, "level": level, "tau": tau, "t_final": t_final},
        "provenance": {"config_hash": "0"}}


@pytest.fixture(scope="module")
def failing_record(tmp_path_factory):
    """A real run that breaks down at once (maxiter = 1, its robust continuation too),
    written by the run store's job."""
    root = str(tmp_path_factory.mktemp("runs"))
    spec = spec_of("ddfv", "sphere", 2, solver={"method": "bicgstab", "rtol": 1e-9,
                                                "maxiter": 1})
    compute(spec, "c0de", root)
    return Path(record_path(spec, root)), store_settings(spec, "c0de")


def test_run_that_breaks_down_is_a_record_with_status_and_no_l2(failing_record):
    path, settings = failing_record
    raw = json.loads(path.read_text())
    assert raw["status"] == "solver_failed" and raw["l2_error"] is None
    assert raw["t_failed"] == pytest.approx(0.01)
    # the T monitor of every time level reached (here only n = 0) is kept
    assert len(raw["series"]["t_min_barycentric"]) == 1
    assert 0.3 < raw["series"]["t_min_barycentric"][0] < 1 / 3
    rec = read_record(path, settings)
    assert np.isnan(rec["l2_error"]) and rec["settings"] == settings
    summary = monitor_summary(rec)
    assert summary["t_reached"] == 0.0
    assert summary["t_monitor_end"] == raw["series"]["t_min_barycentric"][0]
    assert np.isnan(summary["t_exit"])


def test_failed_row_in_the_convergence_table_has_no_eoc_against_it(failing_record):
    path, settings = failing_record
    failed = read_record(path, settings)
    records = {("ddfv", 1): record("ddfv", 1), ("ddfv", 2): failed,
               ("ddfv", 3): record("ddfv", 3)}
    table = level_table(records, ["ddfv"], [1, 2, 3])
    row = table.set_index("level").loc[2]
    assert row["status"] == "solver_failed" and row["t_failed"] == pytest.approx(0.01)
    assert np.isnan(row["l2_error"]) and np.isnan(row["l2_ratio"])
    assert table["eoc"].isna().all()   # level 2 failed: no EOC at 2 nor at 3
    assert row["label"] == SCHEMES["ddfv"].label
    docs = convergence_documents(table, ["ddfv"], SETTINGS)
    assert "failed (t = 0.01)" in docs["md"] and "## Runs that did not finish" in docs["md"]
    csv = pd.read_csv(io.StringIO(docs["csv"]))
    assert csv.loc[1, "status"] == "solver_failed" and np.isnan(csv.loc[1, "l2_error"])


@pytest.mark.parametrize("status", ["t_escaped", "inverted", "solver_breakdown",
                                    "solver_stagnated", "degenerated"])
def test_new_statuses_are_rows_without_eoc(status):
    records = {("ddfv", lv): record("ddfv", lv, status=status if lv == 2 else "ok")
               for lv in (1, 2, 3)}
    table = level_table(records, ["ddfv"], [1, 2, 3])
    assert table.set_index("level").loc[2, "status"] == status
    assert table["eoc"].isna().all()
    docs = convergence_documents(table, ["ddfv"], SETTINGS)
    assert f"DDFV level 2: {status} at t = 0.02" in docs["md"]
    assert f"{status}".replace("_", "\\_") in docs["tex"]


def test_eoc_column_only_between_finished_consecutive_levels():
    orders = eoc_column([1, 2, 3, 4, 6], [1e-2, 2.5e-3, 6.25e-4, 1e-4, 1e-5],
                        ["ok", "ok", "t_escaped", "ok", "ok"])
    np.testing.assert_allclose(orders, [np.nan, 2.0, np.nan, np.nan, np.nan])
    # a finite error in a row marked as failed does not count either
    np.testing.assert_allclose(eoc_column([1, 2], [1e-2, 2.5e-3], ["ok", "solver_failed"]),
                               [np.nan, np.nan])


# -- the beyond aggregation -----------------------------------------------------

SCHEMES_USED = ["ddfv", "ddfv-chord", "cotan"]
LEVELS = [1, 2, 3]
PAPER = ["ddfv", "ddfv-chord"]


def findings(levels, stability, time, space, schemes, paper, t_final, tau_1):
    """The findings as the rule writes them: the study's verdicts in words."""
    return beyond_findings(levels, stability, time, space, schemes, paper, t_final, tau_1,
                           verdicts(levels, stability, schemes, paper))


def synthetic_inputs(finest=()):
    """Records of a small beyond study: the paper variant breaks down on level 3
    with a solver failure after its monitor went below 0, and in the long run
    a T-vertex escapes (t_escaped); chord finishes. The schemes ``finest`` go on
    to level 4 (``beyond.finest``)."""
    failing = [0.33, 0.2, 0.05, -0.5, -3.0]          # outside from n = 3
    records = {}
    for s in SCHEMES_USED:
        for lv in LEVELS + ([4] if s in finest else []):
            if (s, lv) == ("ddfv", 3):
                records[f"runs/{s}/level{lv}.json"] = record(s, lv, status="solver_failed",
                                                             monitor=failing)
            else:
                records[f"runs/{s}/level{lv}.json"] = record(
                    s, lv, l2=(1.0 if s == "ddfv" else 1.05) * 1.3e-2 / 4 ** (lv - 1))
    # a run stopped by an invalid state keeps that state as its last time level
    escaped = record("ddfv", 2, status="t_escaped", t_final=0.12,
                     monitor=[0.33, 0.2, 0.1, -0.01])
    escaped["t_failed"] = 0.03
    long = {"beyond/long/ddfv.json": escaped,
            "beyond/long/ddfv-chord.json": record("ddfv-chord", 2, t_final=0.12)}
    space = {f"beyond/space/{s}/level{lv}.json": record(s, lv, tau=0.0025,
                                                        l2=2e-3 / 4 ** (lv - 1))
             for s in SCHEMES_USED for lv in (1, 2)}
    time_rows = [{"tau": t, "N": round(0.08 / t), "error": 0.3 * t, "eoc": None,
                  "volume_error": 0.1 * t ** 2, "volume_eoc": None, "l2_error": 1e-3,
                  "status": "ok"} for t in (0.01, 0.005, 0.0025)]
    base = {"level": 2, "t_final": 0.08, "reference_tau": 0.0025 / 8}
    time = {"beyond/time/ddfv.json": {"scheme": "ddfv", **base, "outcome": "ok",
                                      "message": "", "rows": time_rows},
            "beyond/time/ddfv-chord.json": {"scheme": "ddfv-chord", **base,
                                            "outcome": "reference_failed",
                                            "message": "reference run failed: ...",
                                            "rows": []},
            "beyond/time/cotan.json": {"scheme": "cotan", **base, "outcome": "ok",
                                       "message": "", "rows": time_rows}}
    beyond = {"levels": LEVELS, "schemes": SCHEMES_USED,
              "finest": {"level": 4, "rtol": 1e-11, "schemes": list(finest)},
              "long_time": {"level": 2, "t_final": 0.12, "tau": 0.01,
                            "schemes": ["ddfv", "ddfv-chord"]},
              "time_study": {"level": 2, "taus": [0.01, 0.005, 0.0025], "reference_factor": 8,
                             "t_final": 0.08, "schemes": ["ddfv", "ddfv-chord", "cotan"]},
              "space_study": {"levels": [1, 2], "tau": 0.0025, "t_final": 0.08,
                              "schemes": SCHEMES_USED},
              "scaling": {"schemes": SCHEMES_USED, "levels": [2, 3], "fit_levels": [2, 3]}}
    inputs = {"levels": [p for p in records if p.startswith("runs/")],
              "long_time": list(long), "space": list(space), "time": list(time)}
    return inputs, {**records, **long, **space, **time}, beyond


@pytest.fixture(scope="module")
def tables():
    inputs, records, beyond = synthetic_inputs()
    tables, series = beyond_tables(inputs, records, beyond, PAPER)
    return tables, series, beyond


def test_levels_table_shows_the_failure_row_without_eoc(tables):
    levels = tables[0]["levels"].set_index(["scheme", "level"])
    failed = levels.loc[("ddfv", 3)]
    assert failed["status"] == "solver_failed"
    assert failed["t_failed"] == pytest.approx(5 * 0.0025)
    assert np.isnan(failed["l2_error"]) and np.isnan(failed["eoc"])
    assert failed["t_monitor_end"] == -3.0 and failed["t_exit"] == pytest.approx(3 * 0.0025)
    assert levels.loc[("ddfv", 2), "eoc"] == pytest.approx(2.0)
    assert levels.loc[("ddfv-chord", 3), "eoc"] == pytest.approx(2.0)
    # every DDFV scheme is compared with the published values, cotan is not
    assert levels.loc[("ddfv-chord", 2), "l2_ratio"] == pytest.approx(
        1.05 * 1.3e-2 / 4 / 3.26e-3)
    assert np.isnan(levels.loc[("cotan", 2), "paper_l2_error"])
    assert list(tables[0]["levels"]["label"].unique()) == [SCHEMES[s].label
                                                           for s in SCHEMES_USED]


def test_stability_table_and_monitor_series(tables):
    stability, series = tables[0]["stability"], tables[1]
    assert set(stability["scheme"]) == {"ddfv", "ddfv-chord"}   # cotan: no T-vertices
    long = stability[stability["study"] == "long_time"].set_index("scheme")
    assert long.loc["ddfv", "status"] == "t_escaped"
    # an escape ends the run: the exit time is the breakdown
    assert long.loc["ddfv", "t_exit"] == pytest.approx(0.03)
    assert long.loc["ddfv", "t_reached"] == pytest.approx(0.03)
    assert long.loc["ddfv", "t_monitor_end"] == -0.01
    assert long.loc["ddfv-chord", "status"] == "ok" and np.isnan(long.loc["ddfv-chord", "t_exit"])
    run = series[(series["scheme"] == "ddfv") & (series["level"] == 3)]
    np.testing.assert_allclose(run["t_monitor"], [0.33, 0.2, 0.05, -0.5, -3.0])
    np.testing.assert_allclose(run["t"], 0.0025 * np.arange(5))
    assert "cotan" not in set(series["scheme"])


def test_finest_level_of_one_scheme_leaves_the_other_rows_alone(tables, tmp_path):
    """beyond.finest: chord goes on to level 4 with its EOC against level 3; the
    rows of every other scheme (and chord's own coarser rows) stay as they are."""
    inputs, records, beyond = synthetic_inputs(finest=["ddfv-chord"])
    tabs, series = beyond_tables(inputs, records, beyond, PAPER)
    levels, plain = tabs["levels"], tables[0]["levels"]
    assert levels[["scheme", "level"]].values.tolist() == [
        *([s, lv] for s in ["ddfv", "ddfv-chord"] for lv in LEVELS), ["ddfv-chord", 4],
        *(["cotan", lv] for lv in LEVELS)]
    finest = levels.set_index(["scheme", "level"]).loc[("ddfv-chord", 4)]
    assert finest["eoc"] == pytest.approx(2.0) and finest["peak_rss_mb"] == 200.0
    assert finest["paper_l2_error"] == 1.95e-4        # published: levels 1-5
    assert np.isnan(finest["wall_time_ratio"])         # no cotan run on level 4
    kept = levels[levels["level"] < 4].reset_index(drop=True)
    pd.testing.assert_frame_equal(kept, plain)
    assert 4 in set(series[series["scheme"] == "ddfv-chord"]["level"])
    docs = beyond_documents(tabs, beyond, SETTINGS, PAPER)
    md = docs["levels"]["md"]
    row = next(line for line in md.splitlines() if line.startswith("| 4 |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    # level, h, tau, N, paper L2/EOC, then DDFV (L2, EOC, /paper), chord (same), cotan
    assert cells[6:9] == ["–"] * 3 and cells[9:11] == ["2.1328e-04", "2.000"]
    assert cells[12:] == ["–"] * 2
    assert "Level 4 ran for DDFV, chord" in md and "peak MB" in md
    cost = next(line for line in md.splitlines()[md.splitlines().index(row) + 1:]
                if line.startswith("| 4 |"))
    cells = [c.strip() for c in cost.strip("|").split("|")]
    # level, N, then iter, CPU s, wall s, peak MB of DDFV, chord, cotan
    assert cells[:2] == ["4", "128"] and cells[2:6] == ["–"] * 4 and cells[10:] == ["–"] * 4
    assert cells[6:10] == ["640", "0.4", "0.4", "200"]
    assert "\\ensuremath{|}gamma\\ensuremath{|} peak MB" in docs["levels"]["tex"]
    for name, doc in docs.items():
        (tmp_path / f"{name}.csv").write_text(doc["csv"])
    read = [pd.read_csv(tmp_path / f"{n}.csv") for n in (
        "levels", "stability", "time_convergence", "space_convergence")]
    text = findings(*read[:4], SCHEMES_USED, PAPER, 0.08, 0.04)
    chord = SCHEMES["ddfv-chord"].label
    assert f"## Level 3 (finest level run by every scheme; level 4 by {chord} only)" in text
    assert (f"- **{chord}** on level 4: L2 2.1328e-04, EOC 2.000 against level 3; 640 "
            "BiCGStab iterations, 0 s wall, 200 MB peak memory.") in text
    assert f"- level 3: {SCHEMES['ddfv'].label} 0 CPU s until it broke down" in text
    figures = beyond_figures(read[0], read[1], series, read[2], read[3], beyond, 0.08)
    write_files({tmp_path / f"{name}.png": fig for name, fig in figures.items()})
    assert (tmp_path / "levels.png").stat().st_size > 1000


def test_time_and_space_tables(tables):
    time = tables[0]["time_convergence"]
    for scheme in ("ddfv", "cotan"):                     # any scheme has a time study
        np.testing.assert_allclose(time[time["scheme"] == scheme]["order"],
                                   [np.nan, 1.0, 1.0])
        np.testing.assert_allclose(time[time["scheme"] == scheme]["volume_order"],
                                   [np.nan, 2.0, 2.0])
    failed = time[time["scheme"] == "ddfv-chord"]
    assert len(failed) == 1 and failed["status"].iloc[0] == "reference_failed"
    space = tables[0]["space_convergence"]
    assert space.groupby("scheme")["eoc"].last().round(6).tolist() == [2.0, 2.0, 2.0]


def test_time_order_is_eoc_for_halved_steps_and_skips_failures():
    order = time_order([0.04, 0.02, 0.01, 0.005], [4.0, 2.0, 1.0, 0.5],
                       ["ok", "ok", "t_escaped", "ok"])
    np.testing.assert_allclose(order, [np.nan, 1.0, np.nan, np.nan])
    np.testing.assert_allclose(time_order([0.03, 0.01], [9.0, 1.0], ["ok"] * 2),
                               [np.nan, 2.0])


def test_documents_and_findings_follow_the_numbers(tables, tmp_path):
    tabs, _, beyond = tables
    docs = beyond_documents(tabs, beyond, SETTINGS, PAPER)
    md = docs["levels"]["md"]
    chord = SCHEMES["ddfv-chord"].label.replace("|", "\\|")
    assert "| DDFV L2 | DDFV EOC | DDFV/paper |" in md and f"{chord}/paper" in md
    assert "failed (t = 0.0125)" in md
    assert "DDFV level 3: solver_failed at t = 0.0125 (step 5 of 32)" in md
    assert "a T-vertex outside its triangle from t = 0.0075" in md
    assert "t_escaped" in docs["stability"]["md"]
    assert r"\begin{tabular}" in docs["levels"]["tex"] and "4^(" not in docs["levels"]["tex"]
    # LaTeX: no bare underscores, < or | in text (headers, captions, cells)
    assert "error at $t_f$" in docs["time_convergence"]["tex"]
    assert "long\\_time" in docs["stability"]["tex"]
    assert "t\\_escaped" in docs["stability"]["tex"]
    assert "<" not in docs["stability"]["tex"].replace("\\ensuremath{<}", "")
    assert "\\ensuremath{|}gamma\\ensuremath{|}" in docs["levels"]["tex"]
    for name, doc in docs.items():
        (tmp_path / f"{name}.csv").write_text(doc["csv"])
    read = [pd.read_csv(tmp_path / f"{n}.csv") for n in (
        "levels", "stability", "time_convergence", "space_convergence")]
    verdict = verdicts(read[0], read[1], SCHEMES_USED, PAPER)
    ratio = 1.05 * 1.3e-2 / 4 ** 2 / 8.01e-4
    assert verdict["stable"] == ["ddfv-chord", "cotan"] and verdict["finest"] == 3
    assert verdict["variants"] == ["ddfv-chord"] and verdict["unstable"] == ["ddfv"]
    assert verdict["reference"] == "ddfv"
    (scheme, level, deviation), = verdict["deviations"]
    assert (scheme, level) == ("ddfv-chord", 3) and deviation == pytest.approx(ratio, rel=1e-6)
    text = findings(*read, SCHEMES_USED, PAPER, 0.08, 0.04)
    label = {s: SCHEMES[s].label for s in SCHEMES_USED}
    assert f"**{label['ddfv']}** (`ddfv`): broke down in 2 of 4 runs" in text
    assert "t_escaped at t = 0.03" in text
    assert f"**{label['ddfv-chord']}** (`ddfv-chord`): every run finished" in text
    assert (f"Stable (every run finished, no T-vertex left its triangle): "
            f"{label['ddfv-chord']}; not stable: {label['ddfv']}.") in text
    assert f"time, **{label['ddfv-chord']}**: no order (reference run failed" in text
    assert f"{label['ddfv-chord']} {100 * (ratio - 1):+.1f} %" in text


def test_plots_from_the_tables(tables, tmp_path):
    tabs, series, beyond = tables
    figures = beyond_figures(tabs["levels"], tabs["stability"], series,
                             tabs["time_convergence"], tabs["space_convergence"], beyond,
                             0.08)
    assert sorted(figures) == ["levels", "space_convergence", "t_monitor", "time_convergence"]
    paths = {tmp_path / f"{name}.{ext}": fig for name, fig in figures.items()
             for ext in ("png", "pdf")}
    write_files(paths)
    assert all(p.stat().st_size > 1000 for p in paths)


def test_space_table_agrees_with_space_convergence(tmp_path):
    log = setup_logging(tmp_path / "runs.log")
    records = {}
    for level in (1, 2):
        spec = spec_of("ddfv", "sphere", level, tau=0.01,
                       solver={"method": "bicgstab", "rtol": 1e-9, "maxiter": 1000})
        records["ddfv", level] = compute(spec, "c", str(tmp_path), log)
    table = space_table(records, ["ddfv"], [1, 2])
    reference = space_convergence("ddfv", "sphere", [1, 2], 0.01)
    np.testing.assert_allclose(table["l2_error"], reference["l2_error"], rtol=1e-12)
    np.testing.assert_allclose(table["eoc"], reference["eoc_l2_error"], rtol=1e-12)


def test_time_study_from_the_stored_final_states_is_time_convergence(tmp_path):
    """The time study's runs are plain specs; its errors, from their saved final states
    and the reference's saved weights, are time_convergence's."""
    from mcfbench.running.run import time_convergence

    plan = {"time_study": {"level": 1, "taus": [0.02, 0.01], "reference_factor": 2,
                           "t_final": 0.04, "schemes": ["cotan"]}}
    specs = {("cotan", tau): spec_of("cotan", "sphere", 1, tau=tau, t_final=0.04,
                                     solver={"method": "bicgstab", "rtol": 1e-9,
                                             "maxiter": 1000})
             for tau in (0.02, 0.01, 0.005)}
    records = {key: compute(spec, "c", str(tmp_path)) for key, spec in specs.items()}
    (rec,) = time_records(specs, records, plan, str(tmp_path))
    assert rec["outcome"] == "ok" and [r["status"] for r in rec["rows"]] == ["ok", "ok"]
    assert rec["rows"][1]["error"] < rec["rows"][0]["error"]
    reference = time_convergence("cotan", "sphere", 1, [0.02, 0.01], reference_factor=2,
                                 t_final=0.04)
    np.testing.assert_array_equal([r["error"] for r in rec["rows"]], reference["error"])
    np.testing.assert_array_equal([r["volume_error"] for r in rec["rows"]],
                                  reference["volume_error"])


# -- the config key `beyond` ----------------------------------------------------

def test_default_config_passes_the_schema_and_the_checks():
    from mcfbench.pipeline import check_config

    config = json.loads(json.dumps(CONFIG))
    check_config(config, REPO / "workflow" / "schemas" / "config.schema.yaml")
    settings = Plans(config, SCHEMAS).plan("beyond")
    assert settings["levels"] == [1, 2, 3, 4, 5, 6]
    assert settings["schemes"] == ["ddfv", "ddfv-chord", "ddfv-eliminate", "cotan",
                                   "ddfv@bdf2", "ddfv-chord@bdf2", "cotan@bdf2"]
    # the time study: every scheme of the registry with each integrator (a scheme that
    # integrates in time itself with its own only)
    assert settings["time_study"]["schemes"] == [
        *SCHEMES, *(f"{s}@{i}" for i in INTEGRATORS if i != "euler" for s in SCHEMES
                    if not SCHEMES[s].integrates_itself)]
    assert "bgn-bdf2" in settings["time_study"]["schemes"]
    assert settings["long_time"]["t_final"] == 0.15 and settings["long_time"]["level"] == 5
    assert settings["time_study"]["taus"] == sorted(settings["time_study"]["taus"],
                                                    reverse=True)
    assert settings["space_study"]["tau"] == pytest.approx(0.04 / 4 ** 6)
    assert all(s.partition("@")[0] in SCHEMES for s in used_schemes(settings))
    # the level-7 run is off by default
    assert settings["finest"] == {"level": 7, "rtol": 1e-11, "schemes": []}
    # the scaling study: every scheme of the registry with the Euler step
    assert {k: v for k, v in settings["scaling"].items() if k != "up_to"} == {
        "schemes": list(SCHEMES), "levels": [2, 3, 4, 5, 6], "fit_levels": [4, 5, 6]}
    assert not [k for k in study_specs(Plans(config, SCHEMAS))["levels"] if k[1] == 7]


def test_finest_level_adds_its_runs_only():
    config = json.loads(json.dumps(CONFIG))
    config["beyond"]["finest"]["schemes"] = ["ddfv-chord"]
    pipeline = Plans(config, SCHEMAS)
    runs = study_specs(pipeline)["levels"]
    default = study_specs(Plans(json.loads(json.dumps(CONFIG)), SCHEMAS))["levels"]
    assert set(runs) - set(default) == {("ddfv-chord", 7)}
    assert all(runs[k] == spec for k, spec in default.items())
    # the finest level's own tolerance; every other run keeps the top-level one, and
    # is Table 3.1's run
    assert runs["ddfv-chord", 7].solver_settings()["rtol"] == 1e-11
    assert {s.solver_settings()["rtol"] for k, s in runs.items() if k[1] != 7} == {1e-9}
    assert runs["ddfv", 3] == sphere_spec(pipeline.plan("convergence"), "ddfv", 3)
    # the time study's own tolerance (config: its BDF3 errors reach 1e-7); default the
    # top-level one
    assert {s.solver_settings()["rtol"] for s in study_specs(pipeline)["time"].values()} \
        == {1e-12}
    del config["beyond"]["time_study"]["rtol"]
    assert {s.solver_settings()["rtol"]
            for s in study_specs(Plans(config, SCHEMAS))["time"].values()} == {1e-9}
    assert levels_of(pipeline.plan("beyond"), "ddfv-chord") == [1, 2, 3, 4, 5, 6, 7]
    assert levels_of(pipeline.plan("beyond"), "ddfv") == [1, 2, 3, 4, 5, 6]
    problem = problem_of(pipeline.plan("convergence"))
    assert problem.time_steps(problem.tau(7)) == 8192
    # the job's Slurm resources cover the single-core estimate of an earlier session
    # (about 630 MB and 860 s) twice over
    runtime = runtime_minutes(7, problem.time_steps(problem.tau(7)))
    assert mem_mb(7) >= 2 * 630 and runtime * 60 >= 2 * 860


@pytest.mark.parametrize("path, value, message", [
    (("levels",), [8], "config key 'beyond.levels.0': 8 is not valid"),
    (("finest", "level"), 8, "config key 'beyond.finest.level': 8 is not valid"),
    (("finest", "schemes"), "ddfv-chord",
     "config key 'beyond.finest.schemes': 'ddfv-chord' is not of type 'array'"),
    (("finest", "extra"), 1, "config key 'beyond.finest': Additional properties"),
    (("schemes",), ["DDFV"], "config key 'beyond.schemes.0': 'DDFV' does not match"),
    (("scaling", "schemes"), "every", "config key 'beyond.scaling.schemes': 'every' is not"),
    (("long_time", "t_final"), 0.3,
     "config key 'beyond.long_time.t_final': 0.3 is greater than or equal to"),
    (("time_study", "taus"), [0.3], "config key 'beyond.time_study.taus': [0.3] is too short"),
    (("time_study", "reference_factor"), 1,
     "config key 'beyond.time_study.reference_factor': 1 is less than the minimum of 2"),
    (("space_study", "tau"), -1e-5,
     "config key 'beyond.space_study.tau': -1e-05 is less than or equal to the minimum of 0"),
    (("extra",), 1, "config key 'beyond': Additional properties are not allowed ('extra'"),
])
def test_beyond_schema_names_the_bad_key(path, value, message):
    """The section ``beyond`` has its own schema, checked with its plan (Plans.plan("beyond")),
    not while Snakemake reads the workflow: the whole config passes the main schema."""
    from mcfbench.pipeline import check_config

    config = json.loads(json.dumps(CONFIG))
    node = config["beyond"]
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    check_config(json.loads(json.dumps(config)), SCHEMAS / "config.schema.yaml")
    with pytest.raises(ConfigError) as err:
        Plans(config, SCHEMAS).plan("beyond")
    assert message in str(err.value)


def test_main_schema_refuses_an_old_key():
    from snakemake.exceptions import WorkflowError
    from snakemake.utils import validate

    config = json.loads(json.dumps(CONFIG))
    config["scheme_modules"] = {"ddfv": "ddfv.sphere"}      # the old key is gone
    with pytest.raises(WorkflowError):
        validate(config, str(SCHEMAS / "config.schema.yaml"))


@pytest.mark.parametrize("path, value, message", [
    (("space_study", "schemes"), ["ddfv", "fem"],
     "config key 'beyond.space_study.schemes': unknown scheme(s) ['fem']; known schemes"),
    (("time_study", "schemes"), ["ddfv", "fem"],
     "config key 'beyond.time_study.schemes': unknown scheme(s) ['fem']"),
    (("long_time", "t_final"), 0.1503,
     "config key 'beyond.long_time.t_final': t_final = 0.1503 is not a whole multiple"),
    (("time_study", "taus"), [0.01, 0.03], "config key 'beyond.time_study.taus'"),
    (("space_study", "tau"), 3e-5, "config key 'beyond.space_study.tau'"),
    (("finest", "schemes"), ["fem"],
     "config key 'beyond.finest.schemes': unknown scheme(s) ['fem']; known schemes"),
    (("finest", "schemes"), ["cotan-voronoi"],
     "config key 'beyond.finest.schemes': ['cotan-voronoi'] not in 'beyond.schemes'"),
    (("finest", "level"), 6,
     "config key 'beyond.finest.level': 6 is not above the levels of 'beyond.levels'"),
    (("finest", "rtol"), float("nan"), "config key 'beyond.finest.rtol': must lie in (0, 1)"),
    (("time_study", "rtol"), 1.0, "config key 'beyond.time_study.rtol': must lie in (0, 1)"),
    (("scaling", "schemes"), ["cotan", "fem"],
     "config key 'beyond.scaling.schemes': unknown scheme(s) ['fem']; known schemes"),
    (("scaling", "up_to"), {"fem": 5},
     "config key 'beyond.scaling.up_to': ['fem'] not in 'beyond.scaling.schemes'"),
    (("scaling", "up_to"), {"cotan": 3},
     "config key 'beyond.scaling.up_to': {'cotan': 3} leaves fewer than 3 levels"),
    (("scaling", "fit_levels"), [6],
     "config key 'beyond.scaling.fit_levels': [6] must be at least two"),
    (("scaling", "fit_levels"), [1, 2],
     "config key 'beyond.scaling.fit_levels': [1, 2] must be at least two of "
     "'beyond.scaling.levels' [2, 3, 4, 5, 6]"),
])
def test_checks_across_keys_name_the_key(path, value, message):
    config = json.loads(json.dumps(CONFIG))
    if path[0] == "finest" and path[1] == "level":
        config["beyond"]["finest"]["schemes"] = ["ddfv-chord"]   # checked when on
    config["beyond"][path[0]][path[1]] = value
    with pytest.raises(ConfigError) as err:
        Plans(config, SCHEMAS).plan("beyond")
    assert message in str(err.value)
    if "unknown" in message:
        assert all(name in str(err.value) for name in SCHEMES)


def test_time_study_takes_any_scheme():
    config = json.loads(json.dumps(CONFIG))
    config["beyond"]["time_study"]["schemes"] = ["cotan", "ddfv"]
    assert Plans(config, SCHEMAS).plan("beyond")["time_study"]["schemes"] == ["cotan", "ddfv"]


FINEST = "beyond={finest: {schemes: [ddfv-chord]}}"   # the command line of config/README.md


def jobs(out, rule):
    """The number of jobs of ``rule`` in the job stats of a dry run."""
    return next(int(line.split()[1]) for line in out.splitlines()
                if line.split()[:1] == [rule])


@pytest.mark.e2e
def test_dry_run_of_beyond_and_a_bad_value(tmp_path):
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy2(REPO / "Snakefile", work / "Snakefile")
    ignore = shutil.ignore_patterns(".snakemake", "__pycache__", "*.pyc")
    for name in ("workflow", "config"):
        shutil.copytree(REPO / name, work / name, ignore=ignore)
    (work / "bad.yaml").write_text("beyond:\n  time_study:\n    schemes: [fem]\n")
    stub = tmp_path / "bin"
    stub.mkdir()
    (stub / "scontrol").write_text("#!/bin/sh\nexit 1\n")
    (stub / "scontrol").chmod(0o755)
    env = {k: v for k, v in os.environ.items() if not k.startswith("SLURM_")}
    env["PATH"] = os.pathsep.join([str(stub), env.get("PATH", "")])
    # the study's own outputs (`beyond` also rebuilds the report)
    targets = ["beyond_tables", "beyond_figures", "beyond_findings", "beyond_scaling"]
    runs = {"good": ["-n", *targets], "bad": ["-n", *targets, "--configfile", "bad.yaml"],
            # --config merges into the config file's `beyond`: the level stays 7
            "finest": ["-n", *targets, "--config", FINEST],
            "bad_finest": ["-n", *targets, "--config",
                           "beyond={finest: {level: 6, schemes: [ddfv-chord]}}"]}
    procs = {k: subprocess.Popen([sys.executable, "-m", "snakemake", *args], cwd=work, env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
             for k, args in runs.items()}
    out = {k: p.communicate(timeout=300)[0] for k, p in procs.items()}
    assert procs["good"].returncode == 0, out["good"][-3000:]
    pipeline = Plans(json.loads(json.dumps(CONFIG)), SCHEMAS)
    runs = study_specs(pipeline)
    for job in ("runs_sphere_", "beyond_tables", "beyond_figures", "beyond_findings",
                "beyond_scaling"):
        assert job in out["good"], job
    assert procs["bad"].returncode != 0
    assert "config key 'beyond.time_study.schemes': unknown scheme(s) ['fem']" in out["bad"], \
        out["bad"][-2000:]
    # the level-7 run: only with beyond.finest, in a batch alone (a heavy run), sized
    # for Slurm
    assert procs["finest"].returncode == 0, out["finest"][-3000:]
    from mcfbench.pipeline import RunStore, batch_resources

    config = json.loads(json.dumps(CONFIG))
    config["beyond"]["finest"]["schemes"] = ["ddfv-chord"]
    (batch,) = [b for b in RunStore(Plans(config, SCHEMAS), ["convergence", "beyond", "matrix"])
                .batches if any(spec.level == 7 for spec in b.specs)]
    assert {spec.scheme for spec in batch.specs} == {"ddfv-chord"}      # its series alone
    job = out["finest"].split(f"rule runs_{batch.name}:")[1].split("\n\n")[0]
    memory, runtime = batch_resources(batch)
    assert f"runtime={runtime}, mem_mb={memory}," in job, job
    problem = problem_of(pipeline.plan("convergence"))
    assert runtime >= runtime_minutes(7, problem.time_steps(problem.tau(7))) and \
        memory >= mem_mb(7)
    # a run of both the L2/EOC table and the scaling study is one run
    assert len(set(runs["levels"].values()) | set(runs["scaling"].values())) \
        < len(runs["levels"]) + len(runs["scaling"])
    assert procs["bad_finest"].returncode != 0
    assert "config key 'beyond.finest.level': 6 is not above" in out["bad_finest"]
    assert not (work / "results").exists()


def test_record_of_other_settings_is_refused(failing_record):
    path, settings = failing_record
    other = {**settings, "study": "space"}
    assert config_hash(other) != config_hash(settings)
    with pytest.raises(RecordError, match="stale"):
        read_record(path, other)


def test_integrator_table_compares_each_scheme_with_its_euler_runs():
    """BDF2 errors 1/4 of Euler's at 1.2 x the cost per step; at equal CPU time the
    BDF2 error interpolated log-log between its levels."""
    from mcfbench.studies.beyond.tables import integrator_table

    rows = []
    for level in (1, 2, 3):
        N = 2 * 4 ** (level - 1)
        for scheme, l2, cpu in (("cotan", 1e-2 / 4 ** level, 0.1 * 8 ** level),
                                ("cotan@bdf2", 0.25e-2 / 4 ** level, 0.12 * 8 ** level)):
            rows.append({"scheme": scheme, "level": level, "tau": 0.04 / 4 ** (level - 1),
                         "N": N, "l2_error": l2, "cpu_seconds": cpu, "status": "ok"})
    table = integrator_table(pd.DataFrame(rows)).set_index("level")
    assert list(table["integrator"]) == ["bdf2"] * 3 and set(table["scheme"]) == {"cotan"}
    np.testing.assert_allclose(table["l2_ratio"], 0.25)
    np.testing.assert_allclose(table["cost_ratio"], 1.2)
    # at Euler's CPU time 0.8 (level 1), BDF2 is between its levels 1 (0.96 s) ... below
    # its coarsest level: no extrapolation
    assert np.isnan(table.loc[1, "equal_cpu_ratio"])
    # level 2: Euler 6.4 s; BDF2's error at 6.4 s on the line through (0.96, 6.25e-4)
    # and (7.68, 1.5625e-4): slope log(1/4)/log(8)
    expected = 6.25e-4 * (6.4 / 0.96) ** (np.log(0.25) / np.log(8))
    assert table.loc[2, "l2_other_at_euler_cpu"] == pytest.approx(expected)
    assert table.loc[2, "equal_cpu_ratio"] == pytest.approx(expected / 6.25e-4)


def test_integrator_findings_read_the_orders_and_the_comparison():
    from mcfbench.studies.beyond.findings import integrator_section
    from mcfbench.studies.beyond.findings import findings as verdicts
    from mcfbench.studies.beyond.tables import integrator_table

    taus = [0.01, 0.005, 0.0025]
    rows = []
    for scheme, point, volume in (("cotan", 1, 1), ("cotan@bdf2", 2, 2), ("bgn", 1, 1),
                                  ("bgn@bdf2", 0.4, 2)):
        errors, volumes = [t ** point for t in taus], [t ** volume for t in taus]
        for tau, error, vol, order, vorder in zip(taus, errors, volumes,
                                                  [np.nan, point, point],
                                                  [np.nan, volume, volume]):
            rows.append({"scheme": scheme, "tau": tau, "order": order,
                         "volume_order": vorder, "status": "ok"})
    time = pd.DataFrame(rows)
    levels = pd.DataFrame([
        {"scheme": s, "level": lv, "tau": 0.04 / 4 ** (lv - 1), "N": 2 * 4 ** (lv - 1),
         "l2_error": l2 / 4 ** lv, "cpu_seconds": cpu * 8 ** lv, "status": "ok"}
        for lv in (1, 2, 3) for s, l2, cpu in (("cotan", 1e-2, 0.1),
                                               ("cotan@bdf2", 0.2e-2, 0.11))])
    table = levels.assign(l2_ratio=np.nan)
    verdict = verdicts(table, pd.DataFrame(columns=["scheme", "status", "t_exit"]),
                       ["cotan", "cotan@bdf2"], [], time, integrator_table(levels))
    assert [r["pointwise"] for r in verdict["time_orders"]["bdf2"][1]] == [True, False]
    text = "\n".join(integrator_section(verdict))
    assert "**euler** (order 1): pointwise order 1.00-1.00 for 2 of 2 schemes." in text
    assert ("**bdf2** (order 2): pointwise order 2.00-2.00 for 1 of 2 schemes; by the volume "
            "between the surfaces only: BGN (2.00; pointwise 0.40).") in text
    assert ("cotangent with bdf2 (level 3): L2 0.20 x Euler's at 1.10 x the CPU per step, "
            in text)


def test_order_table_has_a_row_per_scheme_and_a_column_pair_per_integrator():
    from mcfbench.presentation.formats import MISSING
    from mcfbench.studies.beyond.tables import order_rows

    rows = [{"scheme": s, "order": o, "volume_order": v, "status": "ok"}
            for s, o, v in (("cotan", np.nan, np.nan), ("cotan", 1.0, 1.1), ("cotan", 1.2, 1.1),
                            ("cotan@bdf2", 2.0, 2.0), ("bgn@bdf2", 0.3, 2.1))]
    header, body = order_rows(pd.DataFrame(rows))
    assert header == ["scheme", "euler order", "euler order (volume)", "bdf2 order",
                      "bdf2 order (volume)"]
    assert body[0] == [SCHEMES["cotan"].label, "1.10", "1.10", "2.00", "2.00"]
    assert body[1] == [SCHEMES["bgn"].label, MISSING, MISSING, "0.30", "2.10"]


# -- the scaling study ------------------------------------------------------------

def test_scaling_fits_exact_power_laws_exactly():
    """Records whose CPU seconds per step are 2e-6 n^1.25 (cotan) and 3e-7 n^0.9 (DDFV)
    and whose jobs take 100 MB plus 1e-3 n^1.1 MB (the level-1 run: 100 MB): the fits
    on levels 4-6 give those slopes and coefficients to round-off; a run that broke
    down is left out of the fit, and level 1 is not a point of the study."""
    laws = {"cotan": (2e-6, 1.25, 1e-3, 1.1), "ddfv": (3e-7, 0.9, 4e-3, 1.05)}
    records = {}
    for scheme, (b, q, a, p) in laws.items():
        for level in range(1, 7):
            r = record(scheme, level, status="solver_failed" if (scheme, level) == ("ddfv", 3)
                       else "ok")
            r["cpu_seconds"] = r["N"] * b * r["nV"] ** q
            r["peak_rss_mb"] = 100.0 + (a * r["nV"] ** p if level > 1 else 0.0)
            records[f"runs/{scheme}/level{level}.json"] = r
    _, _, beyond = synthetic_inputs()
    beyond = {**beyond, "levels": list(range(1, 7)), "schemes": list(laws),
              "scaling": {"levels": [2, 3, 4, 5, 6], "fit_levels": [4, 5, 6]}}
    by_level = {(r["scheme"], r["level"]): r for r in records.values()}
    from mcfbench.studies.beyond.tables import beyond_level_table
    from mcfbench.studies.beyond.scaling import power_fit, scaling_table

    levels = beyond_level_table(by_level, {s: list(range(1, 7)) for s in laws}, ["ddfv"])
    table = scaling_table(levels[levels["level"] >= 2], [4, 5, 6]).set_index("scheme")
    for scheme, (b, q, a, p) in laws.items():
        row = table.loc[scheme]
        assert row["fit_levels"] == "4 5 6"
        assert row["step_slope"] == pytest.approx(q, rel=1e-10)
        assert row["step_coefficient"] == pytest.approx(b, rel=1e-8)
        assert row["memory_slope"] == pytest.approx(p, rel=1e-10)
        assert row["memory_coefficient"] == pytest.approx(a, rel=1e-8)
        assert row["fixed_mb"] == 100.0
        assert row["n_max"] == by_level[scheme, 6]["nV"]
    points = levels.set_index(["scheme", "level"])
    assert np.isnan(points.loc[("ddfv", 3), "step_seconds"])       # broke down: no point
    # a scheme with one finished run among the fit levels has no slope
    assert np.isnan(scaling_table(levels[levels["level"] <= 4], [3, 4])
                    .set_index("scheme").loc["ddfv", "step_slope"])
    assert np.isnan(power_fit([10.0, 20.0], [1.0, -1.0])[1])


def test_scaling_study_runs_every_scheme_of_the_registry_unless_narrowed():
    """beyond.scaling.schemes: "all" (the default) is every Euler scheme of the registry
    on every level of beyond.scaling.levels, as specs of the run store, those of the
    L2/EOC table where both run (one run); a list narrows
    it (an integrator's rows only when listed). The records the other tables read
    do not change."""
    default = Plans(json.loads(json.dumps(CONFIG)), SCHEMAS)
    runs = study_specs(default)
    slow = {"cotan-intrinsic", "ddfv-chord-bgn-carried", "ddfv-chord-mdr-carried"}
    assert default.plan("beyond")["scaling"]["up_to"] == {s: 5 for s in slow}
    assert set(runs["scaling"]) == {(s, lv) for s in SCHEMES
                                    for lv in (2, 3, 4, 5, 6) if not (s in slow and lv == 6)}
    shared = set(runs["scaling"]) & set(runs["levels"])
    assert shared == {(s, lv) for s in ("ddfv", "ddfv-chord", "ddfv-eliminate", "cotan")
                      for lv in (2, 3, 4, 5, 6)}
    assert all(runs["scaling"][k] == runs["levels"][k] for k in shared)
    assert all(runs["scaling"][s, lv] == sphere_spec(default.plan("convergence"), s, lv)
               for s in ("bgn", "kll") for lv in (2, 6))
    config = json.loads(json.dumps(CONFIG))
    config["beyond"]["scaling"] = {"schemes": ["kll", "cotan@bdf2"], "levels": [3, 2],
                                   "fit_levels": [2, 3]}
    narrowed = Plans(config, SCHEMAS)
    assert narrowed.plan("beyond")["scaling"] == {
        "schemes": ["kll", "cotan@bdf2"], "levels": [2, 3], "fit_levels": [2, 3], "up_to": {}}
    assert sorted(study_specs(narrowed)["scaling"]) == [
        ("cotan@bdf2", 2), ("cotan@bdf2", 3), ("kll", 2), ("kll", 3)]
    # the tables' records (rule beyond_tables) are those of the other studies only
    tables = {study: study_specs(default)[study] for study in TABLE_STUDIES}
    assert {study: study_specs(narrowed)[study] for study in TABLE_STUDIES} == tables
    assert ("kll", 6) not in tables["levels"]
    del config["beyond"]["scaling"]["schemes"]                     # absent: "all"
    assert Plans(config, SCHEMAS).plan("beyond")["scaling"]["schemes"] == list(SCHEMES)
    # beyond.scaling.up_to: a scheme stops below the finest level, fitted on as many
    # of its own finest levels
    config = json.loads(json.dumps(CONFIG))
    config["beyond"]["scaling"]["up_to"] = {"cotan-intrinsic": 5}
    capped = Plans(config, SCHEMAS)
    scaling = capped.plan("beyond")["scaling"]
    assert scaling_levels(scaling, "cotan-intrinsic") == [2, 3, 4, 5]
    assert scaling_fit_levels(scaling, "cotan-intrinsic") == [3, 4, 5]
    assert scaling_fit_levels(scaling, "cotan") == [4, 5, 6]
    assert set(study_specs(capped)["scaling"]) - set(runs["scaling"]) == {
        (s, 6) for s in slow - {"cotan-intrinsic"}}


def plan_levels(scaling):
    """The levels and fit levels of each scheme of ``scaling`` (as aggregate_scaling)."""
    return ({s: scaling_levels(scaling, s) for s in scaling["schemes"]},
            {s: scaling_fit_levels(scaling, s) for s in scaling["schemes"]})


def test_scaling_table_and_figure_are_written(tmp_path):
    """Rule beyond_scaling from its own records: one row per scheme of
    beyond.scaling.schemes (here one the levels study does not run) and one point
    per run, the memory above the scheme's coarsest run (level 2: 100 MB), CPU
    seconds per step 1e-6 n^1.2 and memory 1e-3 n^1.1 above it on levels 3-4."""
    records = {}
    for scheme in ("cotan", "bgn"):
        for level in (2, 3, 4):
            r = record(scheme, level)
            r["cpu_seconds"] = r["N"] * 1e-6 * r["nV"] ** 1.2
            r["peak_rss_mb"] = 100.0 + (1e-3 * r["nV"] ** 1.1 if level > 2 else 0.0)
            records[f"runs/{scheme}/level{level}.json"] = r
    _, _, beyond = synthetic_inputs()
    beyond = {**beyond, "scaling": {"schemes": ["cotan", "bgn"], "levels": [2, 3, 4],
                                    "fit_levels": [3, 4], "up_to": {}}}
    points, table = scaling_tables(records, *plan_levels(beyond["scaling"]))
    assert points[["scheme", "level"]].values.tolist() == [
        [s, lv] for s in ("cotan", "bgn") for lv in (2, 3, 4)]
    rows = table.set_index("scheme")
    np.testing.assert_allclose(rows["step_slope"], 1.2, rtol=1e-10)
    np.testing.assert_allclose(rows["memory_slope"], 1.1, rtol=1e-10)
    np.testing.assert_allclose(rows["fixed_mb"], 100.0)
    # up_to: bgn stops at level 3 (its level-4 record, were it there, is not read),
    # fitted on levels 2-3 (its memory there: level 2 is the baseline, no slope)
    capped = {**beyond, "scaling": {**beyond["scaling"], "up_to": {"bgn": 3}}}
    capped_points, capped_table = scaling_tables(records, *plan_levels(capped["scaling"]))
    assert ["bgn", 4] not in capped_points[["scheme", "level"]].values.tolist()
    bgn = capped_table.set_index("scheme").loc["bgn"]
    assert bgn["fit_levels"] == "2 3" and bgn["step_slope"] == pytest.approx(1.2, rel=1e-10)
    assert np.isnan(bgn["memory_slope"])
    assert "BGN up to level 3, fitted on its 2 finest levels (`beyond.scaling.up_to`" in \
        scaling_documents(capped_table, capped, SETTINGS)["md"].replace(SCHEMES["bgn"].label,
                                                                        "BGN")
    doc = scaling_documents(table, beyond, SETTINGS)
    md = doc["md"]
    assert "| scheme | levels fitted | unknowns | CPU s/step (finest) | slope CPU/step |" in md
    assert "2 schemes (`beyond.scaling.schemes`) on levels 2, 3, 4" in md
    assert "same machine, one thread per job" in md and "warm-up" in md
    assert "levels 3, 4 (`beyond.scaling.fit_levels`)" in md
    assert "tab:beyond-scaling" in doc["tex"]
    assert len(pd.read_csv(io.StringIO(doc["csv"]))) == 2
    figure = scaling_figure(points, table, [3, 4])
    write_files({tmp_path / "scaling.png": figure})
    assert (tmp_path / "scaling.png").stat().st_size > 1000
