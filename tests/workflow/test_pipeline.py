"""The Snakemake pipeline, run for real on levels 1-2 in a temporary copy.

The copy holds ``Snakefile``, ``workflow/`` and ``config/``; the packages
(ddfv, baselines, mcfbench) are those of this checkout (installed with
``pip install -e .``; ``PYTHONPATH`` makes sure). Checked: the numbers of
``results/tables/convergence.csv`` against Table 3.1, every output, that a
second run has nothing to do, that a bad run record stops the aggregation
with a message naming the file, that bad config values stop before any
job, and that the scripts are thin adapters of the harness.

If the Slurm executor plugin is installed, Snakemake imports it at start-up
and it asks ``scontrol show config``, which takes 10 s to give up when Slurm
is installed but not running. These local runs do not use Slurm, so a
``scontrol`` that fails at once is put first on ``PATH``.
"""

import json
import re
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

from mcfbench.pipeline import Plans
from mcfbench.storage.provenance import BLAS_THREAD_VARIABLES
from mcfbench.storage.records import checksum
from mcfbench.running.identity import identity_digest, run_identity
from mcfbench.storage.run_store import record_path
from mcfbench.studies.convergence.plan import table_specs

pytestmark = pytest.mark.e2e

REPO = Path(__file__).resolve().parents[2]
SCHEMAS = REPO / "workflow" / "schemas"
# the study's own target (rule all also builds the figures of another rule
# file); targets before --config, which takes every following word
RUN = ["--cores", "2", "convergence", "--config", "levels=[1,2]"]
TABLE = Path("results/tables/convergence.csv")
OUTPUTS = [
    "results/tables/convergence.csv", "results/tables/convergence.md",
    "results/tables/convergence.tex", "results/tables/convergence.csv.json",
    "results/figures/convergence.png", "results/figures/convergence.pdf",
]
IGNORE = shutil.ignore_patterns(".snakemake", "__pycache__", "*.pyc")
TIMEOUT = 300


def copy_workflow(dest):
    dest.mkdir(parents=True)
    shutil.copy2(REPO / "Snakefile", dest / "Snakefile")
    for name in ("workflow", "config"):
        shutil.copytree(REPO / name, dest / name, ignore=IGNORE)
    return dest


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    stub = tmp_path_factory.mktemp("bin")
    (stub / "scontrol").write_text("#!/bin/sh\nexit 1\n")
    (stub / "scontrol").chmod(0o755)
    env = {k: v for k, v in os.environ.items() if not k.startswith("SLURM_")}
    env["PATH"] = os.pathsep.join([str(stub), env.get("PATH", "")])
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO), env.get("PYTHONPATH")]))
    return env


def snakemake(workdir, env, *args):
    """Run snakemake in workdir; return (exit code, stdout + stderr)."""
    proc = subprocess.run([sys.executable, "-m", "snakemake", *args], cwd=workdir, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT)
    return proc.returncode, proc.stdout + proc.stderr


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, env):
    work = copy_workflow(tmp_path_factory.mktemp("pipeline") / "work")
    code, out = snakemake(work, env, *RUN)
    assert code == 0, out[-5000:]
    return work


@pytest.fixture(scope="module")
def table(workdir):
    return pd.read_csv(workdir / TABLE)


def store_record(work, scheme, level):
    """The run store's record of (scheme, level) of Table 3.1 (one file in its folder)."""
    (path,) = (work / "results" / "runs" / "sphere" / scheme / f"level{level}").glob("*.json")
    return path


def test_all_outputs_exist(workdir):
    missing = [p for p in OUTPUTS if not (workdir / p).is_file()]
    assert not missing
    for scheme in ("ddfv", "cotan"):
        for level in (1, 2):
            assert store_record(workdir, scheme, level).with_suffix(".npz").is_file()
    assert not list((workdir / "results" / "runs").rglob("*.tmp"))


def test_ddfv_errors_match_table_3_1(table):
    ddfv = table[table["scheme"] == "ddfv"].set_index("level")
    assert ddfv.loc[1, "l2_error"] == pytest.approx(1.34e-2, rel=0.03)
    assert ddfv.loc[2, "l2_error"] == pytest.approx(3.26e-3, rel=0.01)
    assert ddfv.loc[2, "paper_l2_error"] == 3.26e-3
    np.testing.assert_allclose(ddfv["l2_ratio"], ddfv["l2_error"] / ddfv["paper_l2_error"])
    assert ddfv["nV"].tolist() == [122, 482] and ddfv["N"].tolist() == [2, 8]
    assert ddfv.loc[2, "eoc"] == pytest.approx(2.0, abs=0.1)


def test_cotan_rows(table):
    cotan = table[table["scheme"] == "cotan"].set_index("level")
    assert cotan.index.tolist() == [1, 2]
    assert (cotan["status"] == "ok").all()
    assert np.isfinite(cotan["l2_error"]).all() and (cotan["l2_error"] > 0).all()
    assert cotan["nV"].tolist() == [42, 162] and (cotan["nT"] == 0).all()
    assert np.isnan(cotan.loc[1, "eoc"]) and cotan.loc[2, "eoc"] == pytest.approx(2.0, abs=0.15)
    assert cotan["paper_l2_error"].isna().all()
    np.testing.assert_allclose(cotan["wall_time_ratio"], 1.0)


def test_table_layout(table):
    assert table[["scheme", "level"]].values.tolist() == [
        ["ddfv", 1], ["ddfv", 2], ["cotan", 1], ["cotan", 2]]
    for column in ("scheme", "level", "nV", "tau", "N", "l2_error", "eoc", "iterations",
                   "cpu_seconds", "wall_seconds", "status", "t_failed",
                   "t_min_barycentric", "paper_l2_error", "paper_eoc",
                   "paper_iterations", "paper_cpu_seconds", "l2_ratio"):
        assert column in table.columns


def test_provenance(workdir, table):
    sidecar = json.loads((workdir / "results/tables/convergence.csv.json").read_text())
    assert sidecar["config"]["levels"] == [1, 2] and sidecar["config_hash"]
    assert "scheme_modules" not in sidecar["config"]
    assert len(sidecar["inputs"]) == 4
    record = json.loads(store_record(workdir, "cotan", 2).read_text())
    # set once by the Snakefile, inherited by every job
    assert record["provenance"]["blas_threads"] == dict.fromkeys(BLAS_THREAD_VARIABLES, "1")
    assert record["l2_error"] == table.set_index(["scheme", "level"]).loc[
        ("cotan", 2), "l2_error"]
    assert record["settings"]["code"] == identity_digest(run_identity("cotan", "sphere"))
    assert store_record(workdir, "cotan", 2).stem == record["settings"]["key"]
    assert len(record["series"]["t_min_barycentric"]) == record["N"] + 1
    assert record["wall_seconds"] > 0 and record["peak_rss_mb"] > 10   # the job's peak, MB
    assert record["checksum"] == checksum(record)


def test_second_run_has_nothing_to_do(workdir, env):
    code, out = snakemake(workdir, env, *RUN)
    assert code == 0, out[-3000:]
    assert "Nothing to be done" in out


def test_bad_run_records_stop_the_aggregation(workdir, env, tmp_path):
    """The store is a cache: a record damaged, edited or stale (another spec key or code
    digest) is refused by the view that reads it, naming the file."""
    work = tmp_path / "work"
    shutil.copytree(workdir, work, symlinks=True)
    damaged, edited, stale = (store_record(work, s, k) for s, k in
                              (("cotan", 2), ("ddfv", 1), ("ddfv", 2)))
    damaged.write_text('{"scheme": "cotan", "level": 2,')
    record = json.loads(edited.read_text())
    record["iterations"] = 9                     # edited by hand
    edited.write_text(json.dumps(record))
    record = json.loads(stale.read_text())
    record["settings"]["code"] = "0123456789abcdef"   # other code, consistent checksum:
    record["provenance"]["config_hash"] = "0123456789abcdef"   # a stale record
    record["checksum"] = checksum(record)
    stale.write_text(json.dumps(record))
    before = (work / TABLE).read_text()
    code, out = snakemake(work, env, "-R", "convergence_records", *RUN)
    assert code != 0
    assert f"{damaged.relative_to(work)}: not valid JSON" in out
    assert f"{edited.relative_to(work)}: checksum does not match the content" in out
    assert f"{stale.relative_to(work)}: its settings are not the current ones" in out
    assert "3 invalid run record(s)" in out
    assert "Error in rule convergence_records" in out
    # the check is its own job: the tables of the previous good run stay
    assert (work / TABLE).read_text() == before


TIMINGS = ["cpu_seconds", "wall_seconds", "wall_time_ratio"]


def test_killed_run_resumes_to_the_same_tables(workdir, env, tmp_path):
    """SIGKILL in the middle of a run, then --unlock and --rerun-incomplete as the
    README says: the tables equal those of the uninterrupted run (timings aside)."""
    import signal
    import time

    work = copy_workflow(tmp_path / "work")
    proc = subprocess.Popen([sys.executable, "-m", "snakemake", *RUN], cwd=work, env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    runs = work / "results" / "runs"
    deadline = time.monotonic() + TIMEOUT
    while not any(runs.rglob("level*/*.json")) and time.monotonic() < deadline:
        time.sleep(0.05)                 # killed after the first record, mid-pipeline
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    assert not (work / TABLE).exists()
    code, out = snakemake(work, env, "--unlock", *RUN[2:])
    assert code == 0, out[-3000:]
    code, out = snakemake(work, env, *RUN[:2], "--rerun-incomplete", *RUN[2:])
    assert code == 0, out[-3000:]
    resumed = pd.read_csv(work / TABLE).drop(columns=TIMINGS)
    pd.testing.assert_frame_equal(resumed, pd.read_csv(workdir / TABLE).drop(columns=TIMINGS))


BAD_CONFIGS = {  # --config value -> expected part of the message (the key named)
    "levels=[0]": "config key 'levels.0': '0' is not valid under any of the given schemas",
    'levels=["a"]': "config key 'levels.0': 'a' is not valid",
    "levels=2": "config key 'levels': 2 is not of type 'array'",
    "schemes=[ddfv,fem]": "config key 'schemes': unknown scheme(s) ['fem']; known schemes",
    "tau_level_1=-0.04": "config key 'tau_level_1': -0.04 is less than or equal to the minimum",
    "tau_level_1=0.03": "config keys 't_final' and 'tau_level_1'",
    "tau_level_1=nan": "config keys 't_final' and 'tau_level_1': tau must be a positive number",
    "t_final=nan": "config keys 't_final' and 'tau_level_1': t_final must be a positive number",
    "rtol=-1e-9": "config key 'rtol': -1e-09 is less than or equal to the minimum of 0",
    "rtol=nan": "config key 'rtol': must lie in (0, 1), got nan",
    "threads=0": "config key 'threads': 0 is less than the minimum of 1",
    "foo=1": "unknown config key(s) ['foo']; known keys: beyond, gallery,",
    "integrators=[bdf2]": "config key 'integrators': must include euler",
    "integrators=[euler,bdf4]": "config key 'integrators': unknown integrator(s) ['bdf4']",
    "schemes=[ddfv@bdf4]": "config key 'schemes': unknown scheme(s) ['ddfv@bdf4']",
}


def assert_message_only(out, expected):
    """A config error ends Snakemake with ``ConfigError: <expected ...>`` in one line,
    no traceback (mcfbench.pipeline.message_only)."""
    assert f"ConfigError: {expected}" in out, out[-2000:]
    assert "Traceback" not in out and 'File "' not in out, out[-2000:]


def test_bad_config_stops_before_any_job(tmp_path, env):
    work = copy_workflow(tmp_path / "work")
    procs = {setting: subprocess.Popen(
        [sys.executable, "-m", "snakemake", "-n", "convergence", "--config", setting],
        cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        for setting in BAD_CONFIGS}  # side by side: each is a Snakemake start-up
    for setting, proc in procs.items():
        out, _ = proc.communicate(timeout=TIMEOUT)
        assert proc.returncode != 0, setting
        assert_message_only(out, BAD_CONFIGS[setting])
    assert not (work / "results").exists()


def test_a_bad_beyond_value_stops_only_the_beyond_study(tmp_path, env):
    """Each study checks its own config section when its rules join the job graph:
    a bad value under `beyond` (against its schema, or a time step that does not
    divide t_final) stops `beyond` with the key named, not the matrix nor Table 3.1
    (dry runs)."""
    work = copy_workflow(tmp_path / "work")
    (work / "bad.yaml").write_text("beyond:\n  time_study:\n    taus: [0.3, 0.15]\n")
    bad = {"file": ["--configfile", "bad.yaml"],
           "line": ["--config", "beyond={time_study: {taus: [0.3]}}"]}
    runs = {(target, how): ["-n", target, *args] for target in ("beyond", "matrix", "convergence")
            for how, args in bad.items()}
    procs = {key: subprocess.Popen(
        [sys.executable, "-m", "snakemake", *args], cwd=work, env=env,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        for key, args in runs.items()}
    out = {key: proc.communicate(timeout=TIMEOUT)[0] for key, proc in procs.items()}
    assert procs["beyond", "file"].returncode != 0
    assert_message_only(out["beyond", "file"], "config key 'beyond.time_study.taus': "
                        "t_final = 0.08 is not a whole multiple of tau = 0.3")
    assert procs["beyond", "line"].returncode != 0
    assert_message_only(out["beyond", "line"],
                        "config key 'beyond.time_study.taus': ['0.3'] is too short")
    for target in ("matrix", "convergence"):
        for how in bad:
            assert procs[target, how].returncode == 0, out[target, how][-2000:]
            assert "beyond" not in out[target, how].split("Building DAG of jobs")[1]
    # the matrix plans the batches of its runs (those Table 3.1 asks for too among them)
    assert "rule runs_sphere_matrix_batch" in out["matrix", "file"]
    assert not (work / "results").exists()


def test_a_bad_matrix_or_gallery_value_stops_only_its_target(tmp_path, env):
    """The matrix and the gallery check their sections while Snakemake reads their
    rule files: a bad one leaves them without rules and stops only their own target,
    naming the key (dry runs)."""
    work = copy_workflow(tmp_path / "work")
    (work / "bad.yaml").write_text("matrix:\n  schemes: [ddfv, fem]\ngallery:\n  C: -1\n")
    procs = {target: subprocess.Popen(
        [sys.executable, "-m", "snakemake", "-n", target, "--configfile", "bad.yaml"],
        cwd=work, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        for target in ("matrix", "gallery", "beyond_tables", "convergence")}
    out = {target: proc.communicate(timeout=TIMEOUT)[0] for target, proc in procs.items()}
    assert procs["matrix"].returncode != 0
    assert_message_only(out["matrix"], "config key 'matrix.schemes': unknown scheme(s) ['fem']")
    assert procs["gallery"].returncode != 0
    assert_message_only(out["gallery"],
                        "config key 'gallery.C': -1 is less than or equal to the minimum of 0")
    for target in ("beyond_tables", "convergence"):     # (`beyond` adds the report)
        assert procs[target].returncode == 0, out[target][-2000:]
        batches = [line for line in out[target].splitlines() if line.startswith("rule runs_")]
        assert batches and not [b for b in batches if "matrix" in b]
    assert not (work / "results").exists()


SELECT = "matrix={select: {schemes: [cotan, bgn], problems: {sphere: [1, 2]}}}"


def planned_jobs(out):
    """Snakemake's job stats of a dry run: rule -> count."""
    stats = out.split("Job stats:")[1].split("total")[0]
    return {line.split()[0]: int(line.split()[1]) for line in stats.splitlines()
            if len(line.split()) == 2 and line.split()[1].isdigit()}


def test_a_one_line_selection_plans_only_the_named_runs(tmp_path, env):
    """`matrix.select` on the command line: the named schemes on the named problems
    at the named levels, nothing of config.yaml's full matrix (dry run): batches of the
    sphere only, whose runs are the four named (those the other studies ask for too
    in batches of their own)."""
    from mcfbench.pipeline import RunStore

    work = copy_workflow(tmp_path / "work")
    code, out = snakemake(work, env, "-n", "--cores", "2", "matrix", "--config", SELECT)
    assert code == 0, out[-3000:]
    jobs = {r for r in planned_jobs(out) if r.startswith("runs_")}
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    config["matrix"] = {**config["matrix"], **yaml.safe_load(SELECT.split("=", 1)[1])}
    store = RunStore(Plans(config, SCHEMAS))
    asked = store.requests["matrix"]
    assert {f"runs_{b.name}" for b in store.batches if set(b.specs) & set(asked)} == jobs
    assert all(set(b.specs) <= set(asked) for b in store.batches if f"runs_{b.name}" in jobs)
    assert {(s.scheme, s.level) for s in asked} == {(s, k) for s in ("cotan", "bgn")
                                                    for k in (1, 2)}
    assert all(job.startswith("runs_sphere_") for job in jobs)
    assert not (work / "results").exists()


def test_trimming_the_levels_reruns_no_run(tmp_path, env):
    """Which batch a run falls in does not decide whether it is computed: after cotan
    and bgn on sphere 1-2, asking for level 1 alone, one scheme alone (other batches,
    other rules) or the same again rewrites no record; a batch that runs finds its runs
    in the store."""
    work = copy_workflow(tmp_path / "work")
    both = "matrix={select: {schemes: [cotan, bgn], problems: {sphere: [1, 2]}}}"
    code, out = snakemake(work, env, "--cores", "2", "matrix", "--config", both)
    assert code == 0, out[-3000:]
    records = sorted((work / "results" / "runs" / "sphere").rglob("*.json"))
    assert len(records) == 4
    stamps = [(r.stat().st_mtime_ns, r.read_text()) for r in records]
    for schemes, levels in (("[cotan, bgn]", "[1]"), ("[bgn]", "[1, 2]"),
                            ("[cotan]", "[2]"), ("[cotan, bgn]", "[1, 2]")):
        code, out = snakemake(work, env, "--cores", "2", "matrix", "--config",
                              both.replace("[1, 2]", levels).replace("[cotan, bgn]", schemes))
        assert code == 0, out[-3000:]
        assert max(map(len, out.splitlines())) < 1000
    assert [(r.stat().st_mtime_ns, r.read_text()) for r in records] == stamps
    assert sorted((work / "results" / "runs" / "sphere").rglob("*.json")) == records
    code, out = snakemake(work, env, "-n", "--cores", "2", "matrix", "--config", both)
    assert "Nothing to be done" in out


def test_threads_setting_reaches_the_rules_and_the_records(tmp_path, env):
    work = copy_workflow(tmp_path / "work")
    out = subprocess.run(
        [sys.executable, "-m", "snakemake", "-n", "--cores", "2", "convergence", "--config",
         "threads=2", "levels=[1,2]", "schemes=[ddfv]"],
        cwd=work, env=env, capture_output=True, text=True, timeout=TIMEOUT)
    assert out.returncode == 0, out.stderr[-2000:]
    jobs = out.stdout.split("rule runs_sphere_")[1:]
    assert jobs and all("threads: 2" in job.split("\n\n")[0] for job in jobs)
    config = yaml.safe_load((REPO / "config" / "config.yaml").read_text())
    spec = table_specs(Plans({**config, "threads": 2}, SCHEMAS).plan("convergence"))["ddfv", 1]
    assert spec.threads == 2
    assert table_specs(Plans(config, SCHEMAS).plan("convergence"))["ddfv", 1].threads == 1
    assert record_path(spec) != record_path(
        table_specs(Plans(config, SCHEMAS).plan("convergence"))["ddfv", 1])


_ONE_STEP = ("import json; from mcfbench.running.run import run; "
             "r, _ = run('ddfv', 'sphere', 1, t_final=0.04); print(json.dumps(r.metrics))")


def test_jobs_starting_together_on_an_empty_kernel_cache(tmp_path):
    """Two jobs on one empty numba cache: both compile, neither breaks the
    cache or the other's numbers; a later job only loads the kernels."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    procs = [subprocess.Popen([sys.executable, "-c", _ONE_STEP], env=env, text=True,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE)
             for _ in range(2)]
    outs = [proc.communicate(timeout=TIMEOUT) for proc in procs]
    assert [proc.returncode for proc in procs] == [0, 0], outs
    assert outs[0][0] == outs[1][0] and "l2_error" in outs[0][0]
    later = subprocess.run([sys.executable, "-c", _ONE_STEP], capture_output=True, text=True,
                           env={**env, "NUMBA_DEBUG_CACHE": "1"}, timeout=TIMEOUT)
    assert later.returncode == 0, later.stderr
    assert "data loaded from" in later.stdout and "data saved to" not in later.stdout
    assert later.stdout.splitlines()[-1] == outs[0][0].strip()


def test_run_jobs_wait_for_one_kernel_compilation(tmp_path, env):
    work = copy_workflow(tmp_path / "work")
    out = subprocess.run([sys.executable, "-m", "snakemake", "-n", "--cores", "2",
                          "convergence"],
                         cwd=work, env=env, capture_output=True, text=True, timeout=TIMEOUT)
    assert out.returncode == 0, out.stdout[-2000:]
    assert out.stdout.count("rule compile_kernels:") == 1
    jobs = [job.split("\n\n")[0] for job in out.stdout.split("rule runs_")[1:]]
    assert jobs
    assert all(re.search(r"input: results/logs/kernels/[0-9a-f]{16}\.json", job)
               for job in jobs), jobs[0]


def test_a_code_change_compiles_and_reruns_in_one_invocation(tmp_path, env):
    """The kernels' file is named by the runs' code identity: after a change of a
    presentation module the dry run plans no run; after a change of a scheme's
    source it plans the compilation and the runs it redoes together."""
    work = copy_workflow(tmp_path / "work")
    for package in ("baselines", "mcfbench"):                     # ours to change
        shutil.copytree(REPO / package, work / package, ignore=IGNORE)
    env = {**env, "PYTHONPATH": os.pathsep.join([str(work), env["PYTHONPATH"]])}
    target = ["--cores", "1", "convergence", "--config", "levels=[1]", "schemes=[cotan]"]
    code, out = snakemake(work, env, *target)
    assert code == 0, out[-3000:]
    with open(work / "mcfbench" / "studies" / "convergence" / "tables.py", "a") as source:
        source.write("\n# a change of the table's presentation\n")
    dry = subprocess.run([sys.executable, "-m", "snakemake", "-n", *target], cwd=work, env=env,
                         capture_output=True, text=True, timeout=TIMEOUT)
    assert dry.returncode == 0, dry.stdout[-2000:]
    assert "rule compile_kernels:" not in dry.stdout and "rule run_scheme:" not in dry.stdout
    with open(work / "baselines" / "cotan.py", "a") as source:
        source.write("\n# a change of the scheme's source\n")
    dry = subprocess.run([sys.executable, "-m", "snakemake", "-n", *target], cwd=work, env=env,
                         capture_output=True, text=True, timeout=TIMEOUT)
    assert dry.returncode == 0, dry.stdout[-2000:]
    assert dry.stdout.count("rule compile_kernels:") == 1
    assert dry.stdout.count("rule runs_") == 1      # before: compile_kernels alone


SCRIPTS = REPO / "workflow" / "scripts"
OWN_SCRIPTS = ["compile_kernels", "run_batch", "figure", "convergence_table",
               "plot_convergence",
               "beyond_tables", "beyond_plots", "beyond_findings", "beyond_scaling", "report",
               "report_pdf",
               "check_records"]


@pytest.mark.parametrize("name", OWN_SCRIPTS)
def test_scripts_are_thin_adapters_of_the_harness(name):
    """One script per rule, about 50 lines at most, importing the harness only:
    no other script, no sys.path edits, no BLAS pinning of its own."""
    text = (SCRIPTS / f"{name}.py").read_text()
    assert len(text.splitlines()) <= 50
    assert "sys.path" not in text and "OMP_NUM_THREADS" not in text
    imports = [line.split()[1] for line in text.splitlines()
               if line.startswith(("import ", "from "))]
    local = {p.stem for p in SCRIPTS.glob("*.py")}
    assert not [m for m in imports if m.split(".")[0] in local], imports
    assert any(m.startswith("mcfbench") for m in imports)
    if name in ("run_batch", "figure"):    # jobs that run flows
        assert "tune_malloc()" in text


def test_rules_use_the_registry_and_one_code_digest():
    rules = "".join((REPO / "workflow" / "rules" / f"{name}.smk").read_text()
                    for name in ("common", "runs", "convergence", "beyond", "figures", "report"))
    for gone in ("scheme_modules", "code_digest", "_package_dir", "DDFV_MODULE",
                 "importlib", "def _"):
        assert gone not in rules, gone


def test_failed_output_leaves_every_previous_output_in_place(tmp_path):
    from mcfbench.storage.atomic import write_files

    first, second = tmp_path / "table.csv", tmp_path / "table.md"
    write_files({first: "old csv\n", second: "old md\n"})

    import matplotlib.pyplot as plt

    def broken(*args, **kwargs):
        raise RuntimeError("drawing failed")

    fig = plt.figure()
    fig.savefig = broken
    with pytest.raises(RuntimeError, match="drawing failed"):
        write_files({first: "new csv\n", second: "new md\n", tmp_path / "plot.png": fig})
    assert first.read_text() == "old csv\n" and second.read_text() == "old md\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["table.csv", "table.md"]
