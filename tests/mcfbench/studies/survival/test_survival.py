"""The survival study (mcfbench.studies.survival): its plan (the raw corpus's readable
meshes, every bad key named), its tables from records, its findings; and that a study
is its folder, its rule file and its config key (mcfbench.pipeline's discovery)."""

import math

import numpy as np
import pytest

from mcfbench.geometry.committed_meshes import raw_manifest
from mcfbench.pipeline import check_config, run_studies, studies
from mcfbench.running.schemes import SCHEMES
from mcfbench.studies.config import ConfigError
from mcfbench.studies.survival import findings as survival_findings
from mcfbench.studies.survival import plan as survival_plan
from mcfbench.studies.survival import tables as survival_tables


def test_the_plan_takes_the_meshes_the_intake_reads():
    plan = survival_plan.plan({})
    manifest = raw_manifest()
    read = [n for n, m in manifest.items() if m["intake"] == "read"]
    assert list(plan["meshes"]) == read and len(read) >= 30
    assert plan["refused"] == [n for n in manifest if n not in read]
    # every scheme, each beside its remeshed variant (issue #44)
    assert plan["schemes"] == [n for s in SCHEMES for n in (s, f"{s}+remesh")]
    assert plan["strategies"] == ["remesh"] and (plan["C"], plan["steps"]) == (0.1, 40)
    assert {m["thin_features"] for m in plan["meshes"].values()} == {True, False}
    specs = survival_plan.survival_specs(survival_plan.plan({"schemes": ["cotan", "bgn"],
                                                             "strategies": []}))
    assert len(specs) == 2 * len(read)
    spec = specs[("drop", "bgn")]
    assert spec.mesh_sha256 == manifest["drop"]["sha256"] and spec.steps == 40
    assert spec.tau_edge == 0.1 and spec.frames == 2


@pytest.mark.parametrize("section, message", [
    ({"meshes": ["nonesuch"]}, "'survival.meshes': unknown mesh"),
    ({"schemes": ["nonesuch"]}, "'survival.schemes': unknown scheme"),
    ({"C": 0}, "'survival.C': must be > 0"),
    ({"steps": 0}, "'survival.steps': must be >= 1"),
    ({"solver": "nonesuch"}, "'survival.solver': unknown solver"),
    ({"strategies": ["nonesuch"]}, "'survival.strategies': unknown mesh strategy"),
])
def test_a_bad_key_is_named(section, message):
    with pytest.raises(ConfigError, match=message):
        survival_plan.plan(section)


def _record(scheme, status, done, t_failed=math.nan):
    return {"scheme": scheme, "status": status, "N": 40, "steps_done": done, "tau": 0.01,
            "t_failed": t_failed, "min_angle": 20.0, "cpu_seconds": 0.1, "message": ""}


MESHES = {"a": {"thin_features": False, "kind": "CAD"},
          "b": {"thin_features": False, "kind": "scan"},
          "c": {"thin_features": True, "kind": "modelled"}}


def test_the_tables_count_reached_runs_by_thin_features():
    """Reached: every step done ``ok``, or ``extinct`` (the flow's end) at any step; a
    breakdown's first defect over the final time (0.4)."""
    records = [("a", _record("x", "ok", 40)), ("b", _record("x", "extinct", 12, 0.12)),
               ("c", _record("x", "inverted", 4, 0.04)),
               ("a", _record("y", "inverted", 2, 0.02)), ("b", _record("y", "ok", 40)),
               ("c", _record("y", "ok", 40))]
    runs = survival_tables.runs_table(records, MESHES)
    assert runs["reached"].tolist() == [True, True, False, False, True, True]
    np.testing.assert_allclose(runs["defect_fraction"], [np.nan, np.nan, 0.1, 0.05, np.nan,
                                                         np.nan])
    summary = survival_tables.survival_table(runs, ["x", "y"]).set_index("scheme")
    assert summary.loc["x", ["plain_reached", "plain_meshes", "thin_reached", "thin_meshes"]
                       ].tolist() == [2, 2, 0, 1]
    assert summary.loc["y", "plain_share"] == 0.5 and summary.loc["y", "thin_share"] == 1.0
    assert summary.loc["x", "defect_fraction_median"] == pytest.approx(0.1)
    text = survival_tables.survival_markdown(summary.reset_index(), {
        "meshes": MESHES, "refused": ["d"], "steps": 40, "C": 0.1, "solver": "direct",
        "rtol": 1e-9})
    assert "| x | 2/2 (100 %) | 0/1 (0 %) | 2/3 (67 %) |" in text
    words = survival_findings.findings(summary.reset_index(), {"meshes": MESHES, "steps": 40,
                                                               "C": 0.1})
    assert "**Without thin features**: of the mean curvature flows, the most are taken to " \
        "the end by x (2 of 2, 100 %): it meets the target of 90%." in words
    assert "**With thin features** (the flow pinches them): y (1 of 1, 100 %)." in words
    assert "Through the singularities" not in words              # no NAME+surgery run


def test_the_findings_name_the_schemes_that_go_through_the_thin_parts():
    """x+surgery reaches the thin mesh c, y+surgery reaches it too but its
    continuations removed more than the stated share of the area: not counted."""
    exceeded = {**_record("y+surgery", "ok", 40), "surgery_exceeded": True,
                "removed_area_share": 0.17}
    records = [("c", _record("x+surgery", "ok", 40)), ("c", exceeded),
               ("a", _record("x+surgery", "ok", 40)), ("a", _record("y+surgery", "ok", 40))]
    runs = survival_tables.runs_table(records, MESHES)
    assert runs["reached"].tolist() == [True, False, True, True]
    assert runs["through"].tolist() == [False, True, False, False]
    summary = survival_tables.survival_table(runs, ["x+surgery", "y+surgery"])
    assert summary["thin_through"].tolist() == [0, 1]
    words = survival_findings.findings(summary, {"meshes": MESHES, "steps": 40, "C": 0.1,
                                                 "max_removed_share": 0.01})
    assert "x+surgery (1 of 1) took meshes with thin features to the end; y+surgery " \
        "none." in words and "at most 1% of the area" in words
    assert "Runs that went on past a continuation to the end, whatever the share " \
        "removed: y+surgery (1)." in words
    assert "no scheme here goes through a pinch" not in words


def test_the_tables_count_the_rollbacks_of_each_scheme():
    """runs.csv carries each record's ``rollbacks`` (0 for a record written before
    the key); survival.csv and .md the scheme's total and its runs with one or more."""
    records = [("a", {**_record("x+remesh", "ok", 40), "rollbacks": 3}),
               ("b", {**_record("x+remesh", "inverted", 7, 0.07), "rollbacks": 10}),
               ("c", {**_record("x+remesh", "ok", 40), "rollbacks": 0}),
               ("a", _record("x", "inverted", 2, 0.02))]
    runs = survival_tables.runs_table(records, MESHES)
    assert runs["rollbacks"].tolist() == [3, 10, 0, 0]
    summary = survival_tables.survival_table(runs, ["x", "x+remesh"]).set_index("scheme")
    assert summary.loc["x+remesh", ["rollbacks", "rolled_back_runs"]].tolist() == [13, 2]
    assert summary.loc["x", ["rollbacks", "rolled_back_runs"]].tolist() == [0, 0]
    text = survival_tables.survival_markdown(summary.reset_index(), {
        "meshes": MESHES, "refused": [], "steps": 40, "C": 0.1, "solver": "direct",
        "rtol": 1e-9})
    assert "| x+remesh | 1/2 (50 %) | 1/1 (100 %) | 2/3 (67 %) | 13 (2) |" in text
    assert "| x | 0/1 (0 %) | – | 0/1 (0 %) | 0 (0) |" in text


def test_every_scheme_is_paired_with_its_variants_once():
    chosen = survival_plan.plan({"schemes": ["bgn", "mdr+remesh", "mdr", "bgn"],
                                 "strategies": ["remesh", "surgery"]})["schemes"]
    assert chosen == ["bgn", "bgn+remesh", "bgn+surgery", "mdr+remesh", "mdr", "mdr+surgery"]
    assert survival_plan.plan({"schemes": "cotan", "strategies": []})["schemes"] == ["cotan"]


def test_the_paired_table_and_findings_show_each_scheme_beside_its_remeshed_variant():
    records = [("a", _record("x", "inverted", 2, 0.02)), ("b", _record("x", "ok", 40)),
               ("c", _record("x", "inverted", 1, 0.01)),
               ("a", _record("x+remesh", "ok", 40)), ("b", _record("x+remesh", "ok", 40)),
               ("c", _record("x+remesh", "inverted", 3, 0.03)),
               ("a", _record("y", "ok", 40)), ("b", _record("y", "ok", 40)),
               ("c", _record("y", "ok", 40))]
    summary = survival_tables.survival_table(survival_tables.runs_table(records, MESHES),
                                             ["x", "x+remesh", "y"])
    text = survival_tables.paired_markdown(summary, ["remesh"])
    assert "| scheme | none, without thin features | +remesh, without thin features | "         "none, with thin features | +remesh, with thin features |" in text
    assert "| x | 1/2 | 2/2 | 0/1 | 0/1 |" in text
    assert "| y | 2/2 | not run | 1/1 | not run |" in text
    assert survival_tables.paired_markdown(summary, []) == ""
    words = survival_findings.findings(summary, {"meshes": MESHES, "steps": 40, "C": 0.1,
                                                 "strategies": ["remesh"]})
    assert "**+remesh** beside each scheme, without thin features: more meshes taken to "         "the end for 1 of 1 schemes, fewer for 0, as many for 0; the largest gain: x "         "(1 -> 2)." in words


def test_a_study_is_its_folder_its_rule_file_and_its_config_key():
    """Nothing lists the studies: the survival study is found by its folder, its
    runs join the run store's batches and its config key is known, with no entry in
    the pipeline's glue, the Snakefile or the config's schema."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[4]
    assert "survival" in studies() and "survival" in run_studies()
    assert "gallery" not in run_studies()             # it makes its own batches
    assert (root / "workflow/rules/survival.smk").is_file()
    for place in ("Snakefile", "mcfbench/pipeline.py", "workflow/schemas/config.schema.yaml"):
        assert "survival" not in (root / place).read_text(), place
    import yaml

    config = yaml.safe_load((root / "config/config.yaml").read_text())
    schema = root / "workflow/schemas/config.schema.yaml"
    assert "survival" in config
    check_config(config, schema)
    config["survivl"] = config.pop("survival")
    with pytest.raises(ConfigError, match=r"unknown config key\(s\) \['survivl'\]"):
        check_config(config, schema)


def test_conformalized_mcf_is_no_mean_curvature_flow_in_the_verdict():
    """cmcf (its stiffness the initial mesh's) is named apart: the target is a mean
    curvature flow's."""
    records = [("a", _record("cmcf", "ok", 40)), ("b", _record("cmcf", "ok", 40)),
               ("a", _record("bgn", "ok", 40)), ("b", _record("bgn", "inverted", 3, 0.03))]
    summary = survival_tables.survival_table(survival_tables.runs_table(records, MESHES),
                                             ["cmcf", "bgn"])
    words = survival_findings.findings(summary, {"meshes": MESHES, "steps": 40, "C": 0.1})
    assert "the most are taken to the end by bgn (1 of 2, 50 %): it misses" in words
    assert "Conformalized MCF, whose stiffness is the initial mesh's (not a mean curvature " \
        "flow): cmcf (2 of 2, 100 %)." in words
