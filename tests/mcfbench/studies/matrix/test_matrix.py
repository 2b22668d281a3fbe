"""The benchmark matrix (mcfbench.studies.matrix, workflow/rules/matrix.smk): the config
check against the registries, one tiny matrix run for real (2 schemes x 2
problems at level 1) through the job function, records, tables, findings and
plots, the EOC and summary logic on records with known numbers, and the
Snakemake DAG of the targets `matrix` and `gallery`."""

import math
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from mcfbench.running.problems import PROBLEMS
from mcfbench.running.schemes import SCHEMES
from mcfbench.storage.frames import load_frames
from mcfbench.running.batch import compute
from mcfbench.storage.records import FIELDS, read_record, write_record
from mcfbench.storage.run_store import frames_path, read_run, read_runs, record_path
from mcfbench.storage.statuses import STATUSES
from mcfbench.studies.config import ConfigError
from mcfbench.studies.gallery import job as gallery_job
from mcfbench.studies.matrix import aggregate as matrix_aggregate
from mcfbench.studies.matrix import findings as matrix_findings
from mcfbench.studies.matrix import plan as matrix_plan
from mcfbench.studies.matrix import tables as matrix_tables

REPO = Path(__file__).resolve().parents[4]


def computed(specs, root):
    """Every spec run into the run store ``root`` (the batch job's
    :func:`mcfbench.running.batch.compute`, code digest ``"test"``): ``{spec: "test"}``."""
    for spec in specs:
        compute(spec, "test", str(root))
    return dict.fromkeys(specs, "test")


# ------------------------------------------------------------ config


def test_plan_defaults_to_every_scheme_and_problem():
    plan = matrix_plan.plan({})
    assert plan["schemes"] == list(SCHEMES)
    assert list(plan["problems"]) == list(PROBLEMS)
    assert plan["problems"]["sphere"] == sorted(PROBLEMS["sphere"].levels)
    assert plan["solver"] == "bicgstab"


def test_plan_levels_and_leaving_out():
    plan = matrix_plan.plan({"schemes": ["cotan"], "problems": {"sphere": ["2", 1],
                                                                        "torus": []}})
    assert plan["schemes"] == ["cotan"]
    assert plan["problems"]["sphere"] == [1, 2]
    assert "torus" not in plan["problems"]


def test_plan_adds_other_integrators_only_to_the_schemes_run():
    section = {"with_integrators": {"bdf2": ["ddfv-chord-carried", "cotan"]}}
    assert matrix_plan.plan(section)["schemes"] == [*SCHEMES, "ddfv-chord-carried@bdf2",
                                               "cotan@bdf2"]
    assert matrix_plan.plan({**section, "schemes": ["bgn", "cotan"]})["schemes"] == \
        ["bgn", "cotan", "cotan@bdf2"]
    assert matrix_plan.plan({**section, "schemes": ["bgn"]})["schemes"] == ["bgn"]
    with pytest.raises(ConfigError, match=r"unknown scheme\(s\) \['cotn@bdf2'\]"):
        matrix_plan.plan({"schemes": ["bgn"], "with_integrators": {"bdf2": ["cotn"]}})


def test_select_runs_exactly_the_named_schemes_problems_and_levels():
    """`matrix.select` cuts the matrix down to what it names, whatever the rest of
    the section (Snakemake merges --config into config.yaml's section)."""
    full = {"schemes": "all", "with_integrators": {"bdf2": ["cotan"]},
            "problems": {"sphere": [1, 2, 3, 4, 5], "torus": [1, 2]}}
    plan = matrix_plan.plan({**full, "select": {"schemes": ["cotan", "bgn@bdf2"],
                                                "problems": {"torus": [2], "sphere": ["1", 2]}}})
    assert plan["schemes"] == ["cotan", "bgn@bdf2"]          # no cotan@bdf2 added
    assert plan["problems"] == {"sphere": [1, 2], "torus": [2]}   # registry order
    assert plan["selected"] and not matrix_plan.plan(full)["selected"]
    runs = matrix_plan.planned_specs(plan)
    assert len(runs) == 2 * 3
    # either key alone keeps the full matrix's other one
    only_sphere = matrix_plan.plan({**full, "select": {"problems": {"sphere": [1]}}})
    assert only_sphere["schemes"] == [*SCHEMES, "cotan@bdf2"]
    assert only_sphere["problems"] == {"sphere": [1]}
    assert matrix_plan.plan({**full, "select": {"schemes": ["bgn"]}})["problems"] == \
        matrix_plan.plan(full)["problems"]


def test_a_run_is_its_spec_whatever_else_the_plan_holds():
    """A run's spec depends neither on the other levels nor on the other schemes, and
    the matrix's sphere run is Table 3.1's (one run in the store for both studies)."""
    from mcfbench.studies.convergence import plan as convergence

    wide = matrix_plan.plan({"select": {"problems": {"sphere": [1, 2, 3]}}})
    narrow = matrix_plan.plan({"select": {"schemes": ["cotan"], "problems": {"sphere": [1]}}})
    key = ("sphere", "cotan", 1)
    assert matrix_plan.planned_specs(wide)[key] == matrix_plan.planned_specs(narrow)[key]
    table = convergence.plan({"schemes": ["cotan", "ddfv"], "levels": [1, 2, 3], "rtol": 1e-9,
                              "tau_level_1": 0.04, "t_final": 0.08, "threads": 1})
    for (scheme, level), spec in convergence.table_specs(table).items():
        assert matrix_plan.planned_specs(wide)["sphere", scheme, level] == spec
        assert spec.key == matrix_plan.planned_specs(wide)["sphere", scheme, level].key


def test_mesh_problems_get_the_robust_solver():
    plan = matrix_plan.plan({})
    for name, problem in PROBLEMS.items():
        expected = plan["mesh_solver"] if problem.tau_rule == "mesh" else "bicgstab"
        assert matrix_plan.solver_method(plan, name) == expected


def test_a_problem_of_its_own_solver_gets_it_the_others_not():
    own = {"anisotropic_sphere": "kept-ilu-bicgstab", "blobby": "direct"}
    plan = matrix_plan.plan({"problem_solvers": own})
    default = matrix_plan.plan({})
    for name in PROBLEMS:
        expected = own.get(name, matrix_plan.solver_method(default, name))
        assert matrix_plan.solver_method(plan, name) == expected
        level = min(PROBLEMS[name].levels)
        assert matrix_plan.matrix_spec(plan, "cotan", name, level).solver_settings()[
            "method"] == expected


def test_a_cut_down_plan_carries_the_solvers_of_its_problems_only():
    own = {"anisotropic_sphere": "kept-ilu-bicgstab", "blobby": "direct"}
    plan = matrix_plan.plan({"problem_solvers": own,
                             "select": {"problems": {"sphere": [1], "blobby": [1]}}})
    assert plan["problem_solvers"] == {"blobby": "direct"}
    assert matrix_plan.solver_method(plan, "blobby") == "direct"


# ------------------------------------------------------------ a tiny matrix for real


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    """ddfv and cotan on sphere and catenoid, level 1, through the run store's job."""
    root = tmp_path_factory.mktemp("matrix")
    plan = matrix_plan.plan({"schemes": ["ddfv", "cotan"],
                                    "problems": {p: ([1] if p in ("sphere", "catenoid") else [])
                                                 for p in PROBLEMS}})
    runs = computed(matrix_plan.planned_specs(plan).values(), root / "runs")
    table, summary = matrix_aggregate.aggregate(runs, plan, root / "tables", str(root / "runs"))
    return root, plan, runs, table, summary


def test_tiny_records_and_frames(tiny):
    root, plan, runs, table, _ = tiny
    for spec, digest in runs.items():
        record = read_run(spec, digest, str(root / "runs"))
        assert record["status"] in STATUSES
        if record["problem"] == "sphere":
            assert record["status"] == "ok", record["message"]
        if record["status"] != "ok":  # e.g. the paper's DDFV on the catenoid
            assert record["message"].startswith(record["status"])
            assert record["t_failed"] == pytest.approx(record["steps_done"] * record["tau"],
                                                       abs=2 * record["tau"])
        assert record["metric_names"]
        frames = load_frames(frames_path(spec, str(root / "runs")))
        assert len(frames["steps"]) == 2 and frames["steps"][0] == 0
        assert frames["steps"][-1] == record["steps_done"]
    assert not list(root.rglob("*.tmp"))
    sphere = table[(table["problem"] == "sphere") & (table["metric"] == "l2_error")]
    assert set(sphere["scheme"]) == {"ddfv", "cotan"}
    # the paper's level-1 value (Table 3.1: 1.34e-2) within 10 %
    ddfv = sphere[sphere["scheme"] == "ddfv"]["value"].iloc[0]
    assert ddfv == pytest.approx(1.34e-2, rel=0.1)
    assert list(table.columns) == matrix_tables.LONG_COLUMNS


def test_tiny_tables_and_findings(tiny):
    root, plan, runs, table, summary = tiny
    out = root / "tables"
    for name in ("matrix.csv", "sphere.md", "sphere.tex", "catenoid.md", "catenoid.tex",
                 "summary.md", "summary.tex", "summary.csv"):
        assert (out / name).is_file(), name
    for name in ("sphere.md", "catenoid.md", "summary.md"):
        assert "same footing" in (out / name).read_text()
    text = matrix_findings.findings(out / "summary.csv", out / "matrix.csv", root / "findings.md",
                                    plan)
    for problem in plan["problems"]:
        assert f"### {problem}" in text
    for r in summary.itertuples():  # every status is shown, in the tables and the text
        if r.status != "ok":
            assert f"{r.status} at t = {r.t_failed:.4g}" in (out / "summary.md").read_text()
            assert f"{r.status} at t = {r.t_failed:.4g}" in text
    assert "## Across problems" in text
    back = matrix_tables.read_long_table(out / "matrix.csv")
    assert len(back) == len(table)
    assert np.allclose(back["value"], table["value"], equal_nan=True, rtol=1e-9)
    # the mesh quality at start, middle and end of every run, from its record's series
    quality = back[[c for c in matrix_tables.LONG_COLUMNS if c.startswith(("min_angle_",
                                                                             "covolume_ratio_"))]]
    # (a run that broke down before half its final time has no middle)
    reached = back["t_failed"].isna() | (back["t_failed"] >= 0.5 * back["steps"] * back["tau"])
    assert quality.shape[1] == 6 and np.isfinite(quality[reached].to_numpy()).all()
    assert np.isfinite(quality.drop(columns=["min_angle_middle", "covolume_ratio_middle"])
                       .to_numpy()).all()
    assert (back["covolume_ratio_start"] >= 1).all() and (back["min_angle_end"] > 0).all()


def test_tiny_plots(tiny):
    from mcfbench.studies.matrix.plots import (
        error_figure,
        picture_grid,
        quality_figure,
        work_precision_figure,
    )

    root, plan, runs, table, _ = tiny
    problems, schemes = list(plan["problems"]), plan["schemes"]
    figs = root / "figures"
    error_figure(table, [figs / "errors.png"], problems, schemes)
    store = str(root / "runs")
    quality_figure(list(read_runs(runs, root=store).values()), [figs / "quality.png"],
                   problems, schemes)
    entries = {key: (read_run(spec, "test", store), load_frames(frames_path(spec, store)))
               for key, spec in matrix_plan.picture_specs(plan).items()}
    picture_grid(entries, [figs / "pictures.png"], problems, schemes)
    drawn = work_precision_figure(table, [figs / "work_precision.png"], problems, schemes)
    for problem, lines in drawn.items():          # every point is a run's (CPU s, |error|)
        for scheme, (cpu, err) in lines.items():
            metric = matrix_tables.main_metric(problem, table["metric"].unique())
            rows = table[(table["problem"] == problem) & (table["scheme"] == scheme)
                         & (table["metric"] == metric)].sort_values("level")
            np.testing.assert_array_equal(cpu, rows["cpu_seconds"])
            np.testing.assert_array_equal(err, np.abs(rows["value"]))
    assert set(drawn) == {"sphere", "catenoid"} and set(drawn["sphere"]) == set(schemes)
    assert set(drawn["catenoid"]) == {"cotan"}        # ddfv's T-vertex escapes: no error
    for name in ("errors.png", "work_precision.png", "quality.png", "pictures.png"):
        assert (figs / name).stat().st_size > 1000


# ------------------------------------------------------------ EOC and summary on known numbers


def _record(scheme, problem, level, value, status="ok", t_failed=float("nan"),
            metric="l2_error"):
    row = {k: (float("nan") if kind is float else 0 if kind is int else "" if kind is str
               else {} if kind is dict else False) for k, kind in FIELDS.items()
           if k not in ("settings", "provenance", "checksum")}
    row.update(scheme=scheme, problem=problem, level=level, h=0.5 / 2 ** level,
               tau=0.04 / 4 ** level, N=2 * 4 ** level, steps_done=2 * 4 ** level,
               status=status, t_failed=t_failed, min_angle=30.0, max_flipped=0.0,
               iterations=10 * level, cpu_seconds=0.1 * level, solver="bicgstab",
               series={"t": [], "t_min_barycentric": []}, metric_names=[metric])
    row[metric] = value
    return row


def test_a_scheme_whose_runs_reach_extinction_has_a_summary_cell():
    """The torus's BGN runs end ``extinct`` (reached, no level failed: the failed level
    is NaN): the cell says so, with the finest value, instead of ending the tables' job."""
    records = [_record("a", "torus", k + 1, e, "extinct") for k, e in enumerate([4e-2, 1e-2])]
    table = matrix_tables.long_table(records)
    summary = matrix_tables.with_levels(matrix_tables.summary_table(table), table)
    row = summary.iloc[0]
    assert row["status"] == "extinct" and math.isnan(row["failed_level"])
    assert matrix_tables.summary_cell(row) == "EOC 2.00; 1.000e-02 (L2); extinct"


def test_eoc_is_log2_of_the_error_ratio(tmp_path):
    errors = {"a": [1.0e-2, 2.5e-3, 6.0e-4], "b": [2.0e-2, 1.8e-2, 2.1e-2]}
    records = [_record(s, "sphere", k + 1, e) for s, es in errors.items()
               for k, e in enumerate(es)]
    records += [_record("a", "catenoid", 1, -0.01, metric="neck_error"),
                _record("a", "catenoid", 2, float("nan"), "t_escaped", 0.25,
                        metric="neck_error")]
    # through a real record file: NaN as null and back
    path = tmp_path / "r.json"
    write_record(path, records[0], {"x": 1})
    assert read_record(path, settings={"x": 1})["l2_error"] == 1.0e-2
    table = matrix_tables.long_table(records)
    for scheme, es in errors.items():
        eoc = table[(table["scheme"] == scheme) & (table["problem"] == "sphere")]["eoc"]
        assert math.isnan(eoc.iloc[0])
        assert eoc.iloc[1:].tolist() == pytest.approx(
            [math.log2(es[0] / es[1]), math.log2(es[1] / es[2])])
    cat = table[table["problem"] == "catenoid"]
    assert cat["status"].tolist() == ["ok", "t_escaped"]
    assert cat["eoc"].isna().all()
    summary = matrix_tables.summary_table(table)
    a = summary[(summary["problem"] == "sphere") & (summary["scheme"] == "a")].iloc[0]
    assert a["eoc"] == pytest.approx(math.log2(2.5e-3 / 6.0e-4))
    assert a["finest_value"] == 6.0e-4 and a["status"] == "ok"
    c = summary[summary["problem"] == "catenoid"].iloc[0]
    assert c["status"] == "t_escaped" and c["t_failed"] == 0.25 and c["failed_level"] == 2
    lists = matrix_tables.with_levels(summary, table)
    cat = lists[lists["problem"] == "catenoid"].iloc[0]
    assert cat["values"][0] == -0.01 and math.isnan(cat["values"][1])
    assert math.isnan(cat["eocs"][0]) and cat["failed"] == [(2, "t_escaped", 0.25)]
    a_lists = lists[(lists["problem"] == "sphere") & (lists["scheme"] == "a")].iloc[0]
    assert a_lists["values"] == errors["a"] and a_lists["robust_values"] == errors["a"]
    assert a_lists["eocs"] == pytest.approx([math.log2(4.0), math.log2(2.5e-3 / 6.0e-4)])
    assert "t_escaped at t = 0.25 (level 2)" in matrix_tables.summary_cell(cat)
    text = matrix_findings.matrix_findings(table, summary)
    assert "**a** converges at order ~2" in text
    assert "**b** does not converge" in text
    assert "broke down in 1 of 2 runs (level 2: t_escaped at t = 0.25)" in text
    assert "No scheme wins everywhere" in text  # a broke down on the catenoid


def test_recommendation_when_one_scheme_wins():
    records = []
    for scheme, c in (("good", 1.0), ("fine", 3.0)):
        for problem in ("sphere", "hemisphere"):
            records += [_record(scheme, problem, k, c * 4.0 ** -k,
                                metric="l2_error" if problem == "sphere" else "max_height")
                        for k in (1, 2, 3)]
    text = matrix_findings.matrix_findings(matrix_tables.long_table(records))
    assert "**Recommendation: good**" in text


# ------------------------------------------------------------ solver verdicts (issue #24)


def test_solver_failure_is_rerun_with_the_robust_solver(tmp_path):
    """maxiter = 1 forces BiCGStab to fail on the sphere; the job re-runs the level with
    the robust ``jacobi-direct`` (whose Jacobi-BiCGStab fails too at maxiter 1: every
    solve is the sparse LU's), which finishes, and the findings call it a solver verdict."""
    plan = matrix_plan.plan({"schemes": ["cotan", "bgn"], "maxiter": 1,
                             "problems": {p: ([1, 2] if p == "sphere" else []) for p in PROBLEMS}})
    runs = computed(matrix_plan.planned_specs(plan).values(), tmp_path)
    for spec in runs:
        record = read_run(spec, "test", str(tmp_path))
        assert record["status"] == "solver_failed" and "iteration limit 1" in record["message"]
        assert record["robust_status"] == "ok" and record["robust_solver"] == "jacobi-direct"
        assert record["robust_message"] == "" and record["robust_steps_done"] == record["N"]
        assert record["robust_metrics"]["l2_error"] < 2e-2
    table, summary = matrix_aggregate.aggregate(runs, plan, tmp_path / "tables", str(tmp_path))
    assert (table["robust_status"] == "ok").all() and np.isfinite(table["robust_value"]).all()
    cotan = summary[summary["scheme"] == "cotan"].iloc[0]
    assert cotan["runs_ok"] == 0 and cotan["runs_robust_ok"] == 2
    lists = matrix_tables.with_levels(summary, table)
    assert lists[lists["scheme"] == "cotan"].iloc[0]["solver_only"] == [
        (1, "solver_failed", 0.04), (2, "solver_failed", 0.01)]
    assert 1.7 < cotan["robust_eoc"] < 2.3 and cotan["robust_eoc_levels"] == "1-2"
    assert "the robust solver finishes every level" in (tmp_path / "tables" / "summary.md").read_text()
    text = matrix_findings.findings(tmp_path / "tables" / "summary.csv",
                                    tmp_path / "tables" / "matrix.csv", tmp_path / "findings.md",
                                    plan)
    assert "**cotan** converges at order ~2" in text
    assert "A solver verdict, not a scheme verdict: the matrix's solver failed (level 1: " \
           "solver_failed at t = 0.04; level 2: solver_failed at t = 0.01)" in text
    assert "## Solver verdicts" in text and "broke down" not in text


def test_a_run_that_ended_otherwise_is_not_rerun(tmp_path):
    plan = matrix_plan.plan({"schemes": ["cotan"], "problems": {p: ([1] if p == "sphere" else [])
                                                                  for p in PROBLEMS}})
    (spec,) = computed(matrix_plan.planned_specs(plan).values(), tmp_path)
    record = read_run(spec, "test", str(tmp_path))
    assert record["status"] == "ok" and record["robust_status"] == ""
    assert "robust_metrics" not in record


def test_findings_tell_solver_verdicts_from_scheme_verdicts():
    """``a`` fails at level 3 with the solver only (the robust re-run finishes it with an
    order-2 error); ``b`` fails at level 3 with the solver and the robust solver fails
    too: only ``b`` broke down."""
    records = []
    for scheme, c in (("a", 1.0), ("b", 2.0)):
        for k in (1, 2, 3):
            records.append(_record(scheme, "sphere", k, c * 4.0 ** -k))
        records[-1].update(status="solver_failed", t_failed=0.03, l2_error=float("nan"),
                           robust_status="ok" if scheme == "a" else "solver_breakdown",
                           robust_metrics={"l2_error": c * 4.0 ** -3 if scheme == "a" else None})
    table = matrix_tables.long_table(records)
    summary = matrix_tables.with_levels(matrix_tables.summary_table(table), table)
    a = summary[summary["scheme"] == "a"].iloc[0]
    assert a["status"] == "solver_failed" and a["runs_robust_ok"] == 3
    assert a["robust_eoc"] == pytest.approx(2.0) and a["robust_finest_value"] == 4.0 ** -3
    assert a["robust_values"] == pytest.approx([0.25, 4.0 ** -2, 4.0 ** -3])
    b = summary[summary["scheme"] == "b"].iloc[0]
    assert b["runs_robust_ok"] == 2 and b["solver_only"] == []
    ((level, status, t_failed),) = b["robust_failed"]     # the re-run states no time
    assert (level, status) == (3, "solver_breakdown") and math.isnan(t_failed)
    text = matrix_findings.matrix_findings(table)
    assert "**a** converges at order ~2: EOC 2.00 (levels 2-3)" in text
    assert "A solver verdict, not a scheme verdict" in text
    assert "**b** broke down in 1 of 3 runs (level 3: solver_failed at t = 0.03)" in text
    assert "The robust solver failed too (level 3: solver_breakdown): a scheme " \
           "verdict." in text
    assert "a on sphere (level 3: solver_failed at t = 0.03)" in text
    assert "**Recommendation: a**" in text


# ------------------------------------------------------------ the Snakemake DAG


@pytest.mark.e2e
def test_snakemake_dry_run(tmp_path):
    """Both targets resolve to the planned jobs, in a copy of the repository."""
    from mcfbench.pipeline import Plans, RunStore

    work = tmp_path / "work"
    work.mkdir()
    for name in ("Snakefile", "workflow", "config", "ddfv", "baselines", "mcfbench"):
        src = REPO / name
        (shutil.copytree if src.is_dir() else shutil.copy)(
            src, work / name, **({"ignore": shutil.ignore_patterns("__pycache__")}
                                 if src.is_dir() else {}))
    meshes = tmp_path / "meshes"
    gallery_job.write_obj(meshes / "tet.obj", [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                         [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    out = subprocess.run([sys.executable, "-m", "snakemake", "-n", "--cores", "2",
                          "matrix", "gallery", "--config", f"meshes={meshes}"],
                         cwd=work, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-3000:]
    plan = matrix_plan.plan(
        __import__("yaml").safe_load((REPO / "config" / "config.yaml").read_text())["matrix"])
    counts = dict(line.split()[:2] for line in out.stdout.splitlines()
                  if len(line.split()) == 2 and line.split()[1].isdigit())
    specs = set(matrix_plan.planned_specs(plan).values())
    config = __import__("yaml").safe_load((REPO / "config" / "config.yaml").read_text())
    store = RunStore(Plans(config, REPO / "workflow" / "schemas"),
                     ["convergence", "beyond", "matrix"])
    # the batches of the matrix's runs (over every study's specs), one job each
    assert {f"runs_{b.name}" for b in store.batches if specs & set(b.specs)} == \
        {rule for rule in counts if rule.startswith("runs_") and "gallery" not in rule}
    assert all(int(n) == 1 for rule, n in counts.items() if rule.startswith("runs_"))
    assert int(counts["matrix_page"]) == 1  # results/matrix/index.html
    # one mesh file: one batch of every scheme on it
    assert int(counts["runs_gallery_batch1"]) == 1
    assert "gallery_mesh" not in counts  # a folder given: no generated meshes


def test_cheapest_to_reach_reads_the_long_table():
    """The work-precision verdict on known numbers: target = the largest of the
    schemes' smallest errors; per scheme the cheapest run at or below it."""
    from mcfbench.studies.matrix.findings import cheapest_to_reach, work_precision_section

    rows = [("a", 1, 1e-2, 1.0), ("a", 2, 2.5e-3, 4.0), ("b", 1, 4e-3, 3.0), ("b", 2, 1e-3, 9.0)]
    table = pd.DataFrame([{"problem": "sphere", "scheme": s, "level": lv, "metric": "l2_error",
                           "main": True, "value": e, "cpu_seconds": c} for s, lv, e, c in rows])
    (verdict,) = cheapest_to_reach(table)
    assert verdict["target"] == 2.5e-3                    # a's smallest error; b reaches it too
    assert verdict["costs"] == {"a": 4.0, "b": 9.0}
    text = "\n".join(work_precision_section([verdict]))
    assert "sphere (l2_error <= 2.500e-03): **a** is the cheapest, 4 s (then b 9 s)." in text


# ------------------------------------------------------------ findings that read straight (#33)


def _table(rows, problem="sphere", metric="l2_error"):
    """The long table of synthetic runs: ``{scheme: [error per level 1, 2, ...]}``."""
    return matrix_tables.long_table(
        [_record(s, problem, k + 1, e, metric=metric) for s, es in rows.items()
         for k, e in enumerate(es)])


def test_findings_state_their_scope():
    registry_schemes, registry_problems = ["cotan", "bgn", "ddfv"], ["sphere", "torus"]
    cut = {"schemes": ["cotan", "bgn"], "problems": {"sphere": [1, 2]}, "selected": True}
    text = " ".join(matrix_findings.scope_lines(cut, registry_schemes, registry_problems,
                                                {"cotan": "cotangent", "bgn": "bgn"}))
    assert text.startswith("Scope: a cut-down matrix (`matrix.select`): 2 scheme(s) (cotan, "
                           "bgn; the registry has 3) on 1 of the 2 problems, at the levels "
                           "sphere 1, 2.")
    assert "cotan (cotangent)." in text and "bgn (bgn)" not in text  # a label only where it adds
    full = {"schemes": ["cotan", "bgn", "ddfv", "cotan@bdf2"],
            "problems": {"sphere": [1, 2, 3], "torus": [1]}}
    text = " ".join(matrix_findings.scope_lines(full, registry_schemes, registry_problems))
    assert text.startswith("Scope: the full matrix, every scheme of the registry (4 with the "
                           "other integrators) on every problem (2), at the levels sphere 1-3; "
                           "torus 1.")
    table = _table({"cotan": [1e-2, 2.5e-3]})
    assert "Scope: the full" in matrix_findings.matrix_findings(
        table, scope=matrix_findings.scope_lines(full, registry_schemes, registry_problems))


def test_every_problem_with_an_exact_error_is_listed_even_a_real_world_like_one():
    table = pd.concat([_table({"a": [1e-2, 2.5e-3, 6e-4]}),
                       _table({"a": [2e-2, 5e-3, 1.2e-3]}, problem="perturbed_sphere")])
    text = matrix_findings.matrix_findings(table, mesh_problems=["perturbed_sphere"])
    assert "Problems with an exact error: sphere, perturbed_sphere." in text
    assert "Real-world-like meshes (a breakdown disqualifies): perturbed_sphere." in text


def test_a_recommendation_never_hides_an_order_the_verdicts_call_off():
    """On the torus no scheme reaches order ~2, so b (EOC 1.58 there) may still win, but
    the recommendation says what the torus verdict says."""
    table = pd.concat([_table({"b": [1e-2, 2.5e-3, 6.25e-4], "c": [3e-2, 7.5e-3, 1.9e-3]}),
                       _table({"b": [1e-2, 5e-3, 1.67e-3], "c": [1e-2, 6e-3, 3e-3]},
                              problem="torus", metric="volume_error")])
    text = matrix_findings.matrix_findings(table)
    assert "**b** converges at order 1.58 (levels 2-3), not ~2" in text
    assert "**Recommendation: b**" in text
    assert "| torus | 1.58 | 1 | b | not ~2 (no scheme reaches order ~2 there) |" in text


def test_an_eoc_from_two_levels_does_not_disqualify():
    """a: EOC 2.0 on the sphere; b: EOC 2.6 on the sphere from two levels only."""
    table = _table({"a": [1e-2, 2.5e-3], "b": [6e-3, 1e-3]})
    text = matrix_findings.matrix_findings(table)
    assert "**b** converges, EOC 2.58 (levels 1-2): from two levels only, the order is " \
           "not settled" in text
    assert "left out" not in text
    assert "**a** converges at order ~2 from two levels only: EOC 2.00" in text
    assert "**Recommendation: b**" in text and "| a | 2.5 | – | candidate |" in text
    assert "| sphere | 2.58 | 1 | b | from two levels only: the order is not settled |" in text
    three = _table({"a": [4e-2, 1e-2, 2.5e-3], "b": [3.6e-2, 6e-3, 1e-3]})
    text = matrix_findings.matrix_findings(three)           # three levels: it counts
    assert "| b | 1 | – | left out: EOC 2.58 on sphere |" in text
    assert "**Recommendation: a**" in text


def test_an_error_at_a_floor_below_every_order2_scheme_does_not_disqualify():
    """a: order 2 on the sphere down to 2.5e-3; b's error stops decreasing at 1e-3, below
    a's finest: a floor the numbers cannot tell from the problem's, not held against b
    (and said); c stops at 5e-3, above it: left out; d's EOC 2.58 (above the band) still
    disqualifies, however small its error."""
    table = _table({"a": [4e-2, 1e-2, 2.5e-3], "b": [4e-3, 1e-3, 1e-3],
                    "c": [2e-2, 5e-3, 5e-3], "d": [3.6e-2, 6e-3, 1e-3]})
    text = matrix_findings.matrix_findings(table)
    assert "| c | 5 | – | left out: EOC 0.00 on sphere |" in text
    assert "| d | 1 | – | left out: EOC 2.58 on sphere |" in text
    assert "**Recommendation: b**" in text
    assert ("| sphere | 0.00 | 1 | b | at an error no larger than any scheme of order ~2 "
            "there (a floor) |") in text


def test_no_eoc_is_computed_into_an_error_within_the_reference_accuracy():
    """A reference computed by schemes states its accuracy (1e-3 here): d's EOC into 5e-4
    and b's into and at 8e-4 say nothing of their orders, so they are not computed
    (marked in the long table, the summary, the problem table and the findings) and not
    held against them; without the accuracy d's EOC 2.58 above the band leaves it out
    (b's error is at the floor below a's order-2 one either way)."""
    errors = {"a": [4e-2, 1e-2, 2.5e-3], "b": [3.2e-3, 8e-4, 8e-4], "d": [1.8e-2, 3e-3, 5e-4]}
    records = [_record(s, "sphere", k + 1, e) for s, es in errors.items()
               for k, e in enumerate(es)]
    text = matrix_findings.matrix_findings(matrix_tables.long_table(records))
    assert "| d | 1 | – | left out: EOC 2.58 on sphere |" in text
    assert "**Recommendation: b**" in text
    table = matrix_tables.long_table(records, accuracy={"sphere": 1e-3})
    assert (table["reference_accuracy"] == 1e-3).all()
    cut = {s: table[table["scheme"] == s]["eoc_below_accuracy"].tolist() for s in errors}
    assert cut == {"a": [False] * 3, "b": [False, True, True], "d": [False, False, True]}
    d = table[table["scheme"] == "d"]["eoc"].tolist()
    assert math.isnan(d[0]) and d[1] == pytest.approx(math.log2(6)) and math.isnan(d[2])
    summary = matrix_tables.with_levels(matrix_tables.summary_table(table), table)
    row = summary.set_index("scheme").loc["d"]
    assert row["eoc_below_accuracy"] and math.isnan(row["eoc"]) and row["eoc_levels"] == ""
    assert matrix_tables.summary_cell(row) == \
        "EOC n/a (below the reference's accuracy); 5.000e-04 (L3)"
    frame, _ = matrix_tables.problem_table(table, "sphere")
    assert frame.set_index("scheme").loc["d", "EOC"] == \
        "2.58, n/a (below the reference's accuracy)"
    judged = matrix_findings.matrix_findings(table)
    assert "left out" not in judged and "**Recommendation: d**" in judged
    assert ("**d** reaches an error within the reference's accuracy, finest 5.000e-04 "
            "(level 3): EOC n/a (below the reference's accuracy)") in judged
    assert ("| sphere | n/a (below the reference's accuracy) | 1 | d | EOC not computed (an "
            "error within the reference's accuracy) |") in judged
    assert "EOC 2.58 on sphere" not in judged and "-0." not in judged


def test_findings_show_values_as_the_tables_do():
    """A relative error is a number, as in the summary table, never a percentage."""
    table = _table({"a": [-3.2e-2, -8.424e-4]}, problem="catenoid", metric="neck_error")
    text = matrix_findings.matrix_findings(table)
    summary = matrix_tables.with_levels(matrix_tables.summary_table(table), table)
    assert "-8.424e-04" in text and matrix_tables.summary_cell(summary.iloc[0]).count("-8.424e-04")
    assert "%" not in text.split("## Per problem")[1].split("\n## ")[0]


def test_noise_level_timings_are_marked_and_not_ranked():
    fast = {"problem": "sphere", "metric": "l2_error", "target": 1e-3,
            "costs": {"cotan": 0.0045, "bgn": 0.0061, "ddfv": 0.5}}
    text = "\n".join(matrix_findings.work_precision_section([fast]))
    assert "no ranking, the cheapest runs are at the noise level: cotan 0.0045 s (noise " \
           "level), bgn 0.0061 s (noise level), ddfv 0.5 s." in text
    assert "**" not in text.split("ranked:")[1]
    one_fast = {**fast, "costs": {"cotan": 0.0045, "ddfv": 0.5}}
    assert "**cotan** is the cheapest, 0.0045 s (noise level) (then ddfv 0.5 s)." in \
        "\n".join(matrix_findings.work_precision_section([one_fast]))


def test_the_main_metric_is_decided_once_in_the_long_table():
    """Two metrics per run: ``main`` marks the problem's main metric (sphere: l2_error),
    and the summary and the problem table follow the column, not a rule of their own."""
    records = []
    for k, e in ((1, 1e-2), (2, 2.5e-3)):
        r = _record("a", "sphere", k, e)
        r.update(volume=4.0 - k, metric_names=["volume", "l2_error"])
        records.append(r)
    table = matrix_tables.long_table(records)
    assert table.loc[table["main"], "metric"].tolist() == ["l2_error", "l2_error"]
    assert (table["main"] == (table["metric"] == "l2_error")).all()
    assert matrix_tables.summary_table(table)["metric"].tolist() == ["l2_error"]
    swapped = table.assign(main=table["metric"] == "volume")
    (row,) = matrix_tables.summary_table(swapped).to_dict("records")
    assert row["metric"] == "volume" and row["finest_value"] == 2.0
    frame, metric = matrix_tables.problem_table(swapped, "sphere")
    assert metric == "volume" and frame["L2"].tolist() == ["2.000e+00"]


def test_summary_keeps_a_value_measured_before_a_later_breakdown():
    """The torus's volume at t = 0.1 is measured before the run stops at the pinch:
    the summary shows it and its EOC, and still names the breakdown."""
    rows = [("cotan", 1, 0.0156, "solver_stagnated"), ("cotan", 2, 0.0039, "inverted")]
    table = pd.DataFrame([{"scheme": s, "problem": "torus", "level": lv, "h": 0.1 / lv,
                           "tau": 0.004, "steps": 50, "steps_done": 30, "metric": "volume_error",
                           "main": True, "value": v, "eoc": np.nan, "status": st, "t_failed": 0.13,
                           "min_angle": 20.0, "max_flipped": 0, "t_min_barycentric": np.nan,
                           "iterations": 10, "cpu_seconds": 1.0, "robust_status": "",
                           "robust_value": np.nan, "robust_t_failed": np.nan}
                          for s, lv, v, st in rows])
    summary = matrix_tables.summary_table(matrix_tables.add_eoc(table))
    (row,) = summary.to_dict("records")
    assert row["finest_value"] == 0.0039 and row["eoc"] == pytest.approx(2.0, abs=1e-9)
    assert row["runs_ok"] == 0 and row["status"] == "solver_stagnated"


def test_a_pinch_after_the_measurement_is_judged_by_the_measured_error():
    from mcfbench.studies.matrix.verdicts import classify as classify_row

    row = {"runs": 3, "runs_ok": 0, "error": True, "values": [0.164, 0.0463, 0.0129],
           "eoc": 1.84}
    assert classify_row(row) == "order2"
    assert classify_row({**row, "values": [0.164, 0.0463, float("nan")]}) == "broke_down"


def test_figures_fit_a_laptop_column_with_text_of_8_pt_at_least(monkeypatch, tmp_path):
    """Every problem of the registry, two schemes (one of them breaking down, so the
    notes are drawn): the error, work-precision and quality figures are at most
    12.4 in wide (a 1280 px page's column at print size, as the page shows them) and
    no visible text is below SMALLEST_TEXT points."""
    from matplotlib.text import Text

    from mcfbench.presentation.plots import SMALLEST_TEXT
    from mcfbench.studies.matrix import plots

    figures = []
    monkeypatch.setattr(plots, "save_figure", lambda fig, *paths: figures.append(fig))
    records = []
    for problem, entry in PROBLEMS.items():
        metric = entry.main_metric
        for scheme, c in (("cotan", 1.0), ("ddfv", 2.0)):
            for k in (1, 2):
                broke = scheme == "ddfv" and k == 2
                r = _record(scheme, problem, k, float("nan") if broke else c * 4.0 ** -k,
                            status="inverted" if broke else "ok",
                            t_failed=0.01 if broke else float("nan"), metric=metric)
                r["series"] = {"t": [0.0, 0.01], "t_min_barycentric": [0.3, -0.9],
                               "quality_t": [0.0, 0.01], "min_angle": [30.0, 20.0]}
                records.append(r)
    table = matrix_tables.long_table(records)
    problems, schemes = list(PROBLEMS), ["cotan", "ddfv"]
    plots.error_figure(table, [tmp_path / "e.png"], problems, schemes)
    plots.work_precision_figure(table, [tmp_path / "w.png"], problems, schemes)
    plots.quality_figure(records, [tmp_path / "q.png"], problems, schemes)
    assert len(figures) == 3
    for fig in figures:
        assert fig.get_size_inches()[0] <= 1190 / 96, fig.get_suptitle()
        fig.canvas.draw()
        sizes = [t.get_fontsize() for t in fig.findobj(Text)
                 if t.get_visible() and t.get_text().strip()]
        assert sizes and min(sizes) >= SMALLEST_TEXT, (fig.get_suptitle(), min(sizes))
        texts = " ".join(t.get_text() for t in fig.findobj(Text))
        if "main metric" in fig.get_suptitle():
            assert "slope 2" in texts and "broke down: " in texts
        if "quality" in fig.get_suptitle():
            assert "clipped at -0.5" in texts


def test_the_real_meshes_get_a_survival_count_and_a_breakdown_there_disqualifies():
    """#28: per scheme, on how many real meshes it reached the final time, its median
    error there; a breakdown on a real mesh leaves the scheme out of the recommendation."""
    records = [_record("a", p, k + 1, e, metric="area_error")
               for p in ("real_nut", "real_spot") for k, e in enumerate([8e-2, 2e-2])]
    records += [_record("b", "real_nut", 1, 6e-2, metric="area_error"),
                _record("b", "real_nut", 2, 1.5e-2, metric="area_error"),
                _record("b", "real_spot", 1, 7e-3, metric="area_error"),
                _record("b", "real_spot", 2, float("nan"), "inverted", 0.001,
                        metric="area_error")]
    text = matrix_findings.matrix_findings(matrix_tables.long_table(records),
                                           mesh_problems=["real_nut", "real_spot"])
    section = text.split("## On the real meshes")[1].split("## ")[0]
    assert "- **a**: 2 of 2, median error 2.000e-02." in section
    assert "- **b**: 1 of 2, median error 1.500e-02; broke down on real_spot." in section
    assert "**Recommendation: a**" in text
    assert "| a | 1.15 | 0 of 2 | recommended |" in text
    assert "| b | 1 | 1 of 2 | left out: broke down on real_spot |" in text
    assert "On the 2 real-world-like meshes 1 of the 2 schemes break down at least once " \
        "(most often b, on 1)." in text
    assert "| real_nut | 2.00 | 1.33 | b | – |" in text          # b more accurate there


def test_an_extinct_run_reached_its_end():
    """Issue #44, item 3: a run on a real mesh that ends ``extinct`` (the surface
    vanished round, the flow's end; no error measured at the final time) counts as
    reached in the summary and the findings; a ``degenerated`` one at the same time (a
    collapse that is not round) stays a breakdown."""
    errors = [1.0e-2, 2.5e-3, float("nan")]
    records = [_record(scheme, "real_nut", k + 1, e, status=end if k == 2 else "ok",
                       t_failed=0.25 if k == 2 else np.nan, metric="area_error")
               for scheme, end in (("a", "extinct"), ("b", "degenerated"))
               for k, e in enumerate(errors)]
    table = matrix_tables.long_table(records)
    summary = matrix_tables.summary_table(table)
    a, b = (summary[summary["scheme"] == s].iloc[0] for s in "ab")
    assert a["runs_ok"] == 3 and a["status"] == "extinct" and a["runs_robust_ok"] == 3
    assert b["runs_ok"] == 2 and b["status"] == "degenerated" and b["failed_level"] == 3
    assert b["runs_robust_ok"] == 2
    text = matrix_findings.matrix_findings(table, summary)
    assert "- **a**: 1 of 1, median error 2.500e-03." in text
    assert "- **b**: 0 of 1; broke down on real_nut." in text
