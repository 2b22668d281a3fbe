"""The run store in the pipeline (workflow/rules/runs.smk): a run two studies ask for
is computed once, which batch a run falls in does not decide whether it is recomputed,
and an edit reruns exactly the runs whose code it changed.

Each test runs Snakemake for real in a temporary copy of the workflow, on the sphere
at levels 1-2. The edit tests copy the packages too (``PYTHONPATH`` puts the copy
first): a run's code identity is the import closure of its scheme, its problem and the
harness's stepping code (``mcfbench.running.identity``), so an edit of the findings
reruns no run, one of ``baselines/bgn.py`` bgn's alone among cotan, bgn and DDFV, one
of ``ddfv/`` DDFV's alone, and so does a changed option of bgn's registry entry.
"""

import json
import os
import shutil
from pathlib import Path

import pytest

from test_pipeline import copy_workflow, env, snakemake  # noqa: F401  (env: a fixture)

pytestmark = pytest.mark.e2e

REPO = Path(__file__).resolve().parents[2]
IGNORE = shutil.ignore_patterns(".snakemake", "__pycache__", "*.pyc")
SPHERE = "problems: {sphere: [1, 2]}"
THREE = f"matrix={{select: {{schemes: [cotan, bgn, ddfv-chord-carried], {SPHERE}}}}}"

def records(work):
    """``{record path: (mtime, text)}`` of every record of the work's run store."""
    return {p.relative_to(work): (p.stat().st_mtime_ns, p.read_text())
            for p in (work / "results" / "runs").rglob("level*/*.json")}


def schemes_of(work, paths):
    return sorted({json.loads((work / p).read_text())["scheme"] for p in paths})


def test_the_convergence_study_then_the_matrix_compute_the_shared_runs_once(tmp_path, env):
    work = copy_workflow(tmp_path / "work")
    code, out = snakemake(work, env, "--cores", "2", "convergence", "--config",
                          "levels=[1,2]")
    assert code == 0, out[-3000:]
    table = records(work)
    assert len(table) == 4 and schemes_of(work, table) == ["cotan", "ddfv"]
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config",
                          f"matrix={{select: {{schemes: [ddfv, cotan, bgn], {SPHERE}}}}}")
    assert code == 0, out[-3000:]
    after = records(work)
    assert {p: after[p] for p in table} == table        # Table 3.1's runs, untouched
    assert len(after) == 6 and schemes_of(work, set(after) - set(table)) == ["bgn"]
    computed = [r for m in (work / "results" / "runs" / "batches").glob("*.json")
                for r in json.loads(m.read_text())["runs"] if r["computed"]]
    assert len(computed) == 6                  # every run computed once, over both targets
    # the matrix's sphere rows are Table 3.1's numbers
    import pandas as pd

    conv = pd.read_csv(work / "results" / "tables" / "convergence.csv").set_index(
        ["scheme", "level"])
    long = pd.read_csv(work / "results" / "matrix" / "tables" / "matrix.csv")
    for row in long[long["metric"] == "l2_error"].itertuples():
        if row.scheme in ("ddfv", "cotan"):
            assert row.value == pytest.approx(conv.loc[(row.scheme, row.level), "l2_error"],
                                              rel=1e-9)   # the CSVs: 10 digits


def test_a_cut_down_matrix_then_the_full_one_leaves_its_records_alone(tmp_path, env):
    work = copy_workflow(tmp_path / "work")
    cut = "matrix={select: {schemes: [cotan], problems: {sphere: [1]}}}"
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config", cut)
    assert code == 0, out[-3000:]
    before = records(work)
    assert len(before) == 1
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config", THREE)
    assert code == 0, out[-3000:]
    after = records(work)
    assert len(after) == 6 and {p: after[p] for p in before} == before


@pytest.fixture(scope="module")
def edited(tmp_path_factory, env):
    """A copy of the repository (workflow and packages) after the three-scheme matrix;
    its environment."""
    work = copy_workflow(tmp_path_factory.mktemp("edits") / "work")
    for name in ("ddfv", "baselines", "kept_factor", "mcfbench"):
        shutil.copytree(REPO / name, work / name, ignore=IGNORE)
    env = {**env, "PYTHONPATH": os.pathsep.join([str(work), env["PYTHONPATH"]])}
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config", THREE)
    assert code == 0, out[-3000:]
    return work, env


def test_editing_a_presentation_module_reruns_no_run(edited):
    work, env = edited
    before = records(work)
    with open(work / "mcfbench" / "studies" / "matrix" / "findings.py", "a") as source:
        source.write("\n# a change of the findings' wording\n")
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config", THREE)
    assert code == 0, out[-3000:]
    assert "rule runs_" not in out
    assert records(work) == before


def _rewritten_by(edited, source, comment=None, replace=None):
    """The records rewritten when ``source`` (a path below the copy) gets ``comment``
    appended, or ``replace`` (``(old, new)``, old found once) made in it, and the
    three-scheme matrix is run again (its views, the tables and pictures, read every
    record against the current code's digest): ``(changed paths, every path before,
    every path after)``."""
    work, env = edited
    before = records(work)
    text = (work / source).read_text()
    if replace is not None:
        assert text.count(replace[0]) == 1, replace
        (work / source).write_text(text.replace(*replace))
    else:
        (work / source).write_text(f"{text}\n# {comment}\n")
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config", THREE)
    assert code == 0, out[-3000:]
    after = records(work)
    return sorted(p for p in before if after[p] != before[p]), before.keys(), after.keys()


def test_editing_bgn_rewrites_only_bgns_records(edited):
    changed, before, after = _rewritten_by(edited, "baselines/bgn.py",
                                           "a change of the scheme's source")
    assert schemes_of(edited[0], changed) == ["bgn"] and len(changed) == 2
    assert after == before


def test_editing_ddfv_rewrites_only_ddfv_records(edited):
    changed, before, after = _rewritten_by(edited, "ddfv/flow.py",
                                           "a change of the paper's scheme")
    assert schemes_of(edited[0], changed) == ["ddfv-chord-carried"] and len(changed) == 2
    assert after == before


def test_changing_a_registry_option_recomputes_exactly_its_runs(edited):
    """A value of the scheme's registry entry (bgn's row scaling, ``mcfbench/schemes/``:
    a listing, not hashed as code, its options part of the identity as values) reruns
    bgn's two runs alone, with the new option: their records carry the new settings and
    numbers, and the views read them (the matrix ends)."""
    work, _ = edited
    old = {p: json.loads(text) for p, (_, text) in records(work).items()}
    changed, before, after = _rewritten_by(
        edited, "mcfbench/schemes/bgn.py",
        replace=('{"scaling": "mass"}', '{"scaling": "none"}'))
    assert schemes_of(work, changed) == ["bgn"] and len(changed) == 2
    assert after == before
    for path in changed:
        new = json.loads((work / path).read_text())
        assert new["settings"]["code"] != old[path]["settings"]["code"]
        assert new["l2_error"] != old[path]["l2_error"]       # run again, not copied


def test_the_jobs_run_the_code_that_snakemake_planned_with(tmp_path, env):
    """Snakemake in a checkout whose packages are not those of ``PYTHONPATH`` (a
    worktree beside an editable install; here the copy against the repository) plans
    with the checkout's, the Snakefile's folder coming first; its jobs import them too (``mcfbench.pipeline.jobs_pythonpath``): bgn's runs with the copy's
    changed option, whose records the views read (the jobs imported the repository's
    before, and the pictures stopped on a record stale to their code)."""
    work = copy_workflow(tmp_path / "work")
    for name in ("ddfv", "baselines", "kept_factor", "mcfbench"):
        shutil.copytree(REPO / name, work / name, ignore=IGNORE)
    source = work / "mcfbench" / "schemes" / "bgn.py"
    text = source.read_text()
    assert text.count('{"scaling": "mass"}') == 1
    source.write_text(text.replace('{"scaling": "mass"}', '{"scaling": "none"}'))
    assert str(work) not in env["PYTHONPATH"]
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config",
                          "matrix={select: {schemes: [bgn], problems: {sphere: [1]}}}")
    assert code == 0, out[-3000:]
    assert len(records(work)) == 1
