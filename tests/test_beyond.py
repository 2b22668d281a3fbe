"""The study beyond Table 3.1 (workflow/rules/beyond.smk, workflow/scripts/beyond*.py).

Runs that break down must end up as rows with their status, the time of
the breakdown, an empty L2 error and no EOC against them; the aggregation
is checked on small synthetic records, the config key ``beyond`` on its
schema and its checks across keys. No level-6 run here.
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

REPO = Path(__file__).resolve().parents[1]
SCRIPTS = REPO / "workflow" / "scripts"
sys.path.insert(0, str(SCRIPTS))

_saved = dict(os.environ)   # run_scheme pins the BLAS threads in os.environ
import beyond_config  # noqa: E402
import beyond_findings  # noqa: E402
import beyond_plots  # noqa: E402
import beyond_tables  # noqa: E402
import convergence_table  # noqa: E402
import run_scheme  # noqa: E402
from run_records import read_record  # noqa: E402

os.environ.clear()
os.environ.update(_saved)

from ddfv.convergence import space_convergence  # noqa: E402
from ddfv.provenance import config_hash  # noqa: E402
from ddfv.sphere import sphere_run  # noqa: E402

CONFIG = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
MODULES = {name: (entry, {}) if isinstance(entry, str) else
           (entry["module"], entry.get("options", {}))
           for name, entry in CONFIG["scheme_modules"].items()}


# -- synthetic records ----------------------------------------------------------

def record(scheme, level, *, status="ok", l2=None, monitor=None, variant=None, tau=None,
           t_final=0.08, nT=None):
    """A run record as run_scheme.py writes it (without the file)."""
    tau = 0.04 / 4 ** (level - 1) if tau is None else tau
    steps = round(t_final / tau)
    ok = status == "ok"
    cotan = scheme == "cotan"
    if monitor is None:
        monitor = [] if cotan else list(np.linspace(0.33, 0.3, steps + 1 if ok else 2))
    return {
        "scheme": scheme, "module": "baselines.cotan" if cotan else "ddfv.sphere",
        "options": {}, "level": level,
        "variant": variant or ("barycentric" if cotan else scheme.partition("-")[2] or "paper"),
        "nV": 10 * 4 ** level + (0 if cotan else 20 * 4 ** level),
        "nF": 10 * 4 ** level, "nT": (0 if cotan else 20 * 4 ** level) if nT is None else nT,
        "tau": tau, "N": steps,
        "l2_error": (1.3e-2 / 4 ** (level - 1) if l2 is None else l2) if ok else float("nan"),
        "iterations": 5 * steps, "cpu_seconds": 0.1 * level, "wall_seconds": 0.1 * level,
        "status": status, "t_failed": float("nan") if ok else (len(monitor)) * tau,
        "t_min_barycentric": float(np.min(monitor)) if len(monitor) else float("nan"),
        "message": "" if ok else f"BiCGStab did not converge at step {len(monitor)}",
        "t_monitor": list(monitor), "t_final": t_final, "rtol": 1e-9,
        "provenance": {"config_hash": "0"}}


@pytest.fixture(scope="module")
def failing_record(tmp_path_factory):
    """A real run that breaks down at once (maxiter = 1), written by run_scheme.py."""
    out = tmp_path_factory.mktemp("runs") / "ddfv-maxiter1" / "level2.json"
    settings = {"scheme": "ddfv-maxiter1", "module": "ddfv.sphere",
                "options": {"maxiter": 1}, "level": 2, "tau": 0.01, "t_final": 0.08,
                "radius": 1.0, "rtol": 1e-9, "code": {}}
    run_scheme.main(settings, out, out.with_suffix(".log"))
    return out, settings


def test_run_that_breaks_down_is_a_record_with_status_and_no_l2(failing_record):
    path, settings = failing_record
    raw = json.loads(path.read_text())
    assert raw["status"] == "solver_failed" and raw["l2_error"] is None
    assert raw["t_failed"] == pytest.approx(0.01)
    # the T monitor of every time level reached (here only n = 0) is kept
    assert len(raw["t_monitor"]) == 1 and 0.3 < raw["t_monitor"][0] < 1 / 3
    rec = read_record(path, settings)
    assert np.isnan(rec["l2_error"]) and rec["variant"] == "paper"
    summary = beyond_tables.monitor_summary(rec)
    assert summary["t_reached"] == 0.0 and summary["t_monitor_end"] == raw["t_monitor"][0]
    assert np.isnan(summary["t_exit"])


def test_failed_row_in_the_convergence_table_has_no_eoc_against_it(failing_record):
    path, settings = failing_record
    failed = read_record(path, settings)
    records = {("ddfv", 1): record("ddfv", 1), ("ddfv", 2): {**failed, "scheme": "ddfv"},
               ("ddfv", 3): record("ddfv", 3)}
    table = convergence_table.build_table(records, ["ddfv"], [1, 2, 3])
    row = table.set_index("level").loc[2]
    assert row["status"] == "solver_failed" and row["t_failed"] == pytest.approx(0.01)
    assert np.isnan(row["l2_error"]) and np.isnan(row["l2_ratio"])
    assert table["eoc"].isna().all()   # level 2 failed: no EOC at 2 nor at 3
    md = convergence_table.markdown(table, ["ddfv"], {"t_final": 0.08, "tau_level_1": 0.04,
                                                      "rtol": 1e-9})
    assert "failed (t = 0.01)" in md and "## Runs that did not finish" in md
    csv = pd.read_csv(io.StringIO(table.to_csv(index=False)))
    assert csv.loc[1, "status"] == "solver_failed" and np.isnan(csv.loc[1, "l2_error"])


def test_eoc_column_only_between_finished_consecutive_levels():
    orders = convergence_table.eoc_column(
        [1, 2, 3, 4, 6], [1e-2, 2.5e-3, 6.25e-4, 1e-4, 1e-5],
        ["ok", "ok", "degenerated", "ok", "ok"])
    np.testing.assert_allclose(orders, [np.nan, 2.0, np.nan, np.nan, np.nan])
    # a finite error in a row marked as failed does not count either
    np.testing.assert_allclose(convergence_table.eoc_column(
        [1, 2], [1e-2, 2.5e-3], ["ok", "solver_failed"]), [np.nan, np.nan])


# -- the beyond aggregation -----------------------------------------------------

SCHEMES = ["ddfv", "ddfv-chord", "cotan"]
LEVELS = [1, 2, 3]


def synthetic_inputs():
    """Records of a small beyond study: the paper variant breaks down on level 3
    and in the long run (its monitor goes below 0 first), chord finishes."""
    failing = [0.33, 0.2, 0.05, -0.5, -3.0]          # outside from n = 3
    records = {}
    for s in SCHEMES:
        for lv in LEVELS:
            if (s, lv) == ("ddfv", 3):
                records[f"runs/{s}/level{lv}.json"] = record(s, lv, status="solver_failed",
                                                             monitor=failing)
            else:
                records[f"runs/{s}/level{lv}.json"] = record(
                    s, lv, l2=(1.0 if s == "ddfv" else 1.05) * 1.3e-2 / 4 ** (lv - 1))
    long = {"beyond/long/ddfv.json": record("ddfv", 2, status="degenerated",
                                            t_final=0.12, monitor=failing),
            "beyond/long/ddfv-chord.json": record("ddfv-chord", 2, t_final=0.12)}
    space = {f"beyond/space/{s}/level{lv}.json": record(s, lv, tau=0.0025,
                                                        l2=2e-3 / 4 ** (lv - 1))
             for s in SCHEMES for lv in (1, 2)}
    time_rows = [{"tau": t, "N": round(0.08 / t), "error": 0.3 * t, "eoc": np.nan,
                  "l2_error": 1e-3, "status": "ok"} for t in (0.01, 0.005, 0.0025)]
    time = {"beyond/time/ddfv.json": {"scheme": "ddfv", "variant": "paper", "level": 2,
                                      "t_final": 0.08, "reference_tau": 0.0025 / 8,
                                      "status": "ok", "message": "", "rows": time_rows},
            "beyond/time/ddfv-chord.json": {"scheme": "ddfv-chord", "variant": "chord",
                                            "level": 2, "t_final": 0.08,
                                            "reference_tau": 0.0025 / 8,
                                            "status": "reference_failed",
                                            "message": "reference run failed: ...",
                                            "rows": []}}
    beyond = {"levels": LEVELS, "schemes": SCHEMES,
              "long_time": {"level": 2, "t_final": 0.12, "tau": 0.01,
                            "schemes": ["ddfv", "ddfv-chord"]},
              "time_study": {"level": 2, "taus": [0.01, 0.005, 0.0025], "reference_factor": 8,
                             "t_final": 0.08, "schemes": ["ddfv", "ddfv-chord"]},
              "space_study": {"levels": [1, 2], "tau": 0.0025, "t_final": 0.08,
                              "schemes": SCHEMES}}
    inputs = {"levels": [p for p in records if p.startswith("runs/")],
              "long_time": list(long), "space": list(space), "time": list(time)}
    return inputs, {**records, **long, **space, **time}, beyond


@pytest.fixture(scope="module")
def tables():
    inputs, records, beyond = synthetic_inputs()
    tables, series = beyond_tables.build_tables(inputs, records, beyond, ["ddfv", "ddfv-chord"])
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
    # every DDFV variant is compared with the published values, cotan is not
    assert levels.loc[("ddfv-chord", 2), "l2_ratio"] == pytest.approx(
        1.05 * 1.3e-2 / 4 / 3.26e-3)
    assert np.isnan(levels.loc[("cotan", 2), "paper_l2_error"])
    assert list(tables[0]["levels"]["variant"].unique()) == ["paper", "chord", "barycentric"]


def test_stability_table_and_monitor_series(tables):
    stability, series = tables[0]["stability"], tables[1]
    assert set(stability["scheme"]) == {"ddfv", "ddfv-chord"}   # cotan: no T-vertices
    long = stability[stability["study"] == "long_time"].set_index("scheme")
    assert long.loc["ddfv", "status"] == "degenerated"
    assert long.loc["ddfv", "t_exit"] == pytest.approx(0.03)
    assert long.loc["ddfv-chord", "status"] == "ok" and np.isnan(long.loc["ddfv-chord", "t_exit"])
    run = series[(series["scheme"] == "ddfv") & (series["level"] == 3)]
    np.testing.assert_allclose(run["t_monitor"], [0.33, 0.2, 0.05, -0.5, -3.0])
    np.testing.assert_allclose(run["t"], 0.0025 * np.arange(5))


def test_time_and_space_tables(tables):
    time = tables[0]["time_convergence"]
    ok = time[time["scheme"] == "ddfv"]
    np.testing.assert_allclose(ok["order"], [np.nan, 1.0, 1.0])
    failed = time[time["scheme"] == "ddfv-chord"]
    assert len(failed) == 1 and failed["status"].iloc[0] == "reference_failed"
    space = tables[0]["space_convergence"]
    assert space.groupby("scheme")["eoc"].last().round(6).tolist() == [2.0, 2.0, 2.0]


def test_time_order_is_eoc_for_halved_steps_and_skips_failures():
    order = beyond_tables.time_order([0.04, 0.02, 0.01, 0.005], [4.0, 2.0, 1.0, 0.5],
                                     ["ok", "ok", "solver_failed", "ok"])
    np.testing.assert_allclose(order, [np.nan, 1.0, np.nan, np.nan])
    np.testing.assert_allclose(beyond_tables.time_order([0.03, 0.01], [9.0, 1.0], ["ok"] * 2),
                               [np.nan, 2.0])


def test_documents_and_findings_follow_the_numbers(tables, tmp_path):
    tabs, _, beyond = tables
    docs = beyond_tables.documents(tabs, beyond, {"t_final": 0.08, "tau_level_1": 0.04,
                                                  "rtol": 1e-9}, SCHEMES, ["ddfv", "ddfv-chord"])
    md = docs["levels"]["md"]
    assert "| ddfv L2 | ddfv EOC | ddfv/paper |" in md and "ddfv-chord/paper" in md
    assert "failed (t = 0.0125)" in md
    assert "ddfv level 3: solver_failed at t = 0.0125 (step 5 of 32)" in md
    assert "below 0 (a T-vertex outside its triangle) from t = 0.0075" in md
    assert r"\begin{tabular}" in docs["levels"]["tex"] and "4^(" not in docs["levels"]["tex"]
    # LaTeX: no bare underscores or < in text (headers, captions, cells)
    assert "error at $t_f$" in docs["time_convergence"]["tex"]
    assert "long\\_time" in docs["stability"]["tex"] and "was $<$ 0" in docs["stability"]["tex"]
    for name, doc in docs.items():
        (tmp_path / f"{name}.csv").write_text(doc["csv"])
    text = beyond_findings.findings(*(pd.read_csv(tmp_path / f"{n}.csv") for n in (
        "levels", "stability", "time_convergence", "space_convergence")), SCHEMES,
        ["ddfv", "ddfv-chord"], 0.08, beyond["long_time"])
    assert "**ddfv** (variant `paper`): broke down in 2 of 4 runs" in text
    assert "**ddfv-chord** (variant `chord`): every run finished" in text
    assert "Stable (every run finished, no T-vertex left its triangle): ddfv-chord; " \
           "not stable: ddfv." in text
    assert "time, **ddfv-chord**: no order (reference run failed" in text
    ratio = 1.05 * 1.3e-2 / 4 ** 2 / 8.01e-4
    assert f"ddfv-chord {100 * (ratio - 1):+.1f} %" in text


def test_plots_from_the_tables(tables, tmp_path):
    tabs, series, beyond = tables
    inputs = {}
    for name, key in (("levels", "levels"), ("stability", "stability"),
                      ("time_convergence", "time"), ("space_convergence", "space")):
        inputs[key] = tmp_path / f"{name}.csv"
        tabs[name].to_csv(inputs[key], index=False)
    inputs["t_monitor"] = tmp_path / "t_monitor.csv"
    series.to_csv(inputs["t_monitor"], index=False)
    outputs = {f"{n}_{e}": tmp_path / f"{n}.{e}" for n in
               ("levels", "t_monitor", "time_convergence", "space_convergence")
               for e in ("png", "pdf")}
    beyond_plots.main(inputs, beyond, 0.08, outputs, tmp_path / "plots.log")
    assert all(p.stat().st_size > 1000 for p in outputs.values())


def test_space_table_agrees_with_space_convergence():
    runs = {("ddfv", lv): sphere_run(lv, tau=0.01).to_dict() for lv in (1, 2)}
    for r in runs.values():
        r.update(scheme="ddfv", t_final=0.08)   # as run_scheme.py adds them
    table = beyond_tables.space_table(runs, ["ddfv"], [1, 2])
    reference = space_convergence([1, 2], 0.01)
    np.testing.assert_allclose(table["l2_error"], reference["l2_error"], rtol=1e-12)
    np.testing.assert_allclose(table["eoc"], reference["eoc"], rtol=1e-12)


# -- the config key `beyond` ----------------------------------------------------

def test_default_config_passes_the_schema_and_the_checks():
    from snakemake.utils import validate

    config = json.loads(json.dumps(CONFIG))
    validate(config, str(REPO / "workflow" / "schemas" / "config.schema.yaml"))
    settings = beyond_config.beyond_settings(config, MODULES)
    assert settings["levels"] == [1, 2, 3, 4, 5, 6]
    assert settings["schemes"] == ["ddfv", "ddfv-chord", "ddfv-eliminate", "cotan"]
    assert settings["long_time"]["t_final"] == 0.15 and settings["long_time"]["level"] == 5
    assert settings["time_study"]["taus"] == sorted(settings["time_study"]["taus"],
                                                    reverse=True)
    assert settings["space_study"]["tau"] == pytest.approx(0.04 / 4 ** 6)
    assert beyond_config.used_schemes(settings)[-1] == "cotan"
    # the variants of the config are the named variants of the package
    from ddfv.variants import VARIANTS
    for name in ("ddfv", "ddfv-chord", "ddfv-eliminate"):
        assert MODULES[name][0] == "ddfv.sphere"
        assert MODULES[name][1].get("variant", "paper") in VARIANTS


@pytest.mark.parametrize("path, value", [
    (("beyond", "levels"), [8]),
    (("beyond", "schemes"), ["DDFV"]),
    (("beyond", "long_time", "t_final"), 0.3),
    (("beyond", "time_study", "taus"), [0.01]),
    (("beyond", "time_study", "reference_factor"), 1),
    (("beyond", "space_study", "tau"), -1e-5),
    (("beyond", "extra"), 1),
])
def test_schema_rejects_bad_beyond_values(path, value):
    from snakemake.exceptions import WorkflowError
    from snakemake.utils import validate

    config = json.loads(json.dumps(CONFIG))
    node = config
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    with pytest.raises(WorkflowError):
        validate(config, str(REPO / "workflow" / "schemas" / "config.schema.yaml"))


@pytest.mark.parametrize("path, value, message", [
    (("space_study", "schemes"), ["ddfv", "fem"],
     "config key 'beyond.space_study.schemes': unknown scheme(s) ['fem']"),
    (("time_study", "schemes"), ["cotan"],
     "config key 'beyond.time_study.schemes': scheme(s) ['cotan'] are not DDFV schemes"),
    (("long_time", "t_final"), 0.1503,
     "config key 'beyond.long_time.t_final': t_final = 0.1503 is not a whole multiple"),
    (("time_study", "taus"), [0.01, 0.03],
     "config key 'beyond.time_study.taus'"),
    (("space_study", "tau"), 3e-5, "config key 'beyond.space_study.tau'"),
])
def test_checks_across_keys_name_the_key(path, value, message):
    config = json.loads(json.dumps(CONFIG))
    config["beyond"][path[0]][path[1]] = value
    with pytest.raises(beyond_config.ConfigError) as err:
        beyond_config.beyond_settings(config, MODULES)
    assert message in str(err.value)


def test_dry_run_of_beyond_and_a_bad_value(tmp_path):
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy2(REPO / "Snakefile", work / "Snakefile")
    ignore = shutil.ignore_patterns(".snakemake", "__pycache__", "*.pyc")
    for name in ("workflow", "config"):
        shutil.copytree(REPO / name, work / name, ignore=ignore)
    (work / "bad.yaml").write_text("beyond:\n  time_study:\n    schemes: [cotan]\n")
    stub = tmp_path / "bin"
    stub.mkdir()
    (stub / "scontrol").write_text("#!/bin/sh\nexit 1\n")
    (stub / "scontrol").chmod(0o755)
    env = {k: v for k, v in os.environ.items() if not k.startswith("SLURM_")}
    env["PATH"] = os.pathsep.join([str(stub), env.get("PATH", "")])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO), env.get("PYTHONPATH")]))
    # the study's own outputs (`beyond` also rebuilds the report, which needs
    # more of the repository than this copy)
    targets = ["beyond_tables", "beyond_figures", "beyond_findings"]
    runs = {"good": ["-n", *targets], "bad": ["-n", *targets, "--configfile", "bad.yaml"]}
    procs = {k: subprocess.Popen([sys.executable, "-m", "snakemake", *args], cwd=work, env=env,
                                 stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
             for k, args in runs.items()}
    out = {k: p.communicate(timeout=300)[0] for k, p in procs.items()}
    assert procs["good"].returncode == 0, out["good"][-3000:]
    for job in ("beyond_run", "beyond_time", "beyond_tables", "beyond_figures",
                "beyond_findings", "results/runs/ddfv-chord/level6.json",
                "results/beyond/runs/long_time/ddfv/level5.json"):
        assert job in out["good"], job
    assert procs["bad"].returncode != 0
    assert "config key 'beyond.time_study.schemes'" in out["bad"], out["bad"][-2000:]
    assert not (work / "results").exists()


def test_record_hash_of_the_beyond_settings_is_checked(failing_record, tmp_path):
    path, settings = failing_record
    other = {**settings, "study": "space"}
    assert config_hash(other) != config_hash(settings)
    with pytest.raises(Exception, match="config hash"):
        read_record(path, other)
