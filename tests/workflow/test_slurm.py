"""The pipeline gives the same numbers through Slurm as when run locally.

Runs the real workflow twice, each in its own copy of the repository (every
git-tracked file, as in the working tree): once with the local executor and
once through the Slurm profile (``profiles/slurm``), and compares
``results/tables/convergence.csv`` from both, leaving out timing columns.
Untracked files are not copied, so a file the pipeline needs but that was
never ``git add``-ed fails here as it would on a fresh clone.

Needs a live Slurm (``sinfo`` on PATH and answering), e.g. the single-node
one of ``bash workflow/ci/local-slurm.sh start``; skipped otherwise. Run with
``pytest -m slurm``. See docs/cluster.md.

Environment (optional, for real clusters):

``SLURM_TEST_TMPDIR``
    directory for the two copies; it must be visible from the compute nodes
    (default: pytest's temporary directory, fine for a single-node Slurm).
``SLURM_TEST_ARGS``
    extra arguments for the Slurm run, e.g.
    ``--default-resources slurm_partition=debug slurm_account=me mem_mb=1000``.
``SLURM_TEST_TIMEOUT``
    seconds allowed for each run (default 900).
``SLURM_TEST_REQUIRE``
    if set to 1, fail instead of skipping when Slurm is not available (for
    CI, where a skip would hide a broken Slurm set-up).
``SLURM_TEST_TARGETS``
    targets for both runs (default: the workflow's default target), e.g.
    ``results/tables/convergence.csv`` to build only what is compared.
``SLURM_TEST_UNTRACKED``
    if set to 1, also copy untracked files that git does not ignore (to test
    work not yet added to git).
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pytestmark = [pytest.mark.slurm, pytest.mark.e2e]

REPO = Path(__file__).resolve().parents[2]
TABLE = Path("results") / "tables" / "convergence.csv"
CONFIG = ["--config", "levels=[1,2]"]
# without git (e.g. an unpacked source archive): the whole tree minus these
# and minus the outputs of earlier runs (results/ except its README.md)
IGNORE_PATTERNS = shutil.ignore_patterns(
    ".git", ".snakemake", ".pytest_cache", ".venv", "__pycache__", "*.pyc", "*.egg-info", "build"
)


def ignore_copy(directory: str, names: list[str]) -> set[str]:
    ignored = set(IGNORE_PATTERNS(directory, names))
    if Path(directory).resolve() == (REPO / "results").resolve():
        ignored |= {name for name in names if name != "README.md"}
    return ignored


TIMEOUT = float(os.environ.get("SLURM_TEST_TIMEOUT", "900"))
USABLE_NODE_STATES = {"idle", "mixed", "allocated", "completing"}


def slurm_unavailable() -> str | None:
    """Why Slurm cannot be used here, or None if it answers."""
    if shutil.which("sinfo") is None:
        return "Slurm not available: `sinfo` is not on PATH"
    try:
        proc = subprocess.run(
            ["sinfo", "--noheader", "--format=%T"],
            capture_output=True,
            text=True,
            timeout=20,
        )
    except subprocess.TimeoutExpired:
        return "Slurm not available: `sinfo` did not answer within 20 s"
    if proc.returncode != 0:
        error = " | ".join(proc.stderr.strip().splitlines())[:300]
        return f"Slurm not available: `sinfo` failed: {error}"
    states = set(proc.stdout.split())
    # a trailing "*" marks a node that does not respond; other suffixes
    # (power saving, reboot, ...) leave it usable
    usable = {s.rstrip("~#!%$@^-").lower() for s in states if not s.endswith("*")}
    if not usable & USABLE_NODE_STATES:
        return f"Slurm is up but has no usable node (node states: {sorted(states)})"
    return None


@pytest.fixture(scope="module")
def slurm():
    reason = slurm_unavailable()
    if reason:
        reason += " (start one with `bash workflow/ci/local-slurm.sh start`)"
        if os.environ.get("SLURM_TEST_REQUIRE") == "1":
            pytest.fail(reason + "; SLURM_TEST_REQUIRE=1 forbids skipping")
        pytest.skip(reason)


def repository_files() -> list[str] | None:
    """Paths (relative to REPO) of the git-tracked files, or None without git."""
    if shutil.which("git") is None:
        return None
    top = subprocess.run(
        ["git", "-C", str(REPO), "rev-parse", "--show-toplevel"], capture_output=True, text=True
    )
    if top.returncode != 0 or Path(top.stdout.strip()).resolve() != REPO.resolve():
        return None  # not a git checkout (or REPO lies inside another one)
    cmd = ["git", "-C", str(REPO), "ls-files", "-z", "--cached"]
    if os.environ.get("SLURM_TEST_UNTRACKED") == "1":
        cmd += ["--others", "--exclude-standard"]
    proc = subprocess.run(cmd, capture_output=True, check=True)
    return sorted({p for p in proc.stdout.decode().split("\0") if p})


def copy_workflow(dest: Path) -> Path:
    """Copy the repository into dest: every git-tracked file, as it is in the
    working tree (tracked files deleted there are left out), so that the run
    sees what a fresh clone of the working tree would see."""
    files = repository_files()
    if files is None:
        shutil.copytree(REPO, dest, ignore=ignore_copy, symlinks=True)
    else:
        dest.mkdir(parents=True)
        for name in files:
            src, target = REPO / name, dest / name
            if not src.exists() and not src.is_symlink():
                continue  # deleted in the working tree, not yet in git
            target.parent.mkdir(parents=True, exist_ok=True)
            if src.is_dir() and not src.is_symlink():  # a submodule
                shutil.copytree(src, target, ignore=IGNORE_PATTERNS, symlinks=True)
            else:
                shutil.copy2(src, target, follow_symlinks=False)
    if not (dest / "Snakefile").is_file():
        pytest.fail(f"{REPO / 'Snakefile'} is missing (or not tracked by git): the pipeline cannot run")
    return dest


def clean_env() -> dict[str, str]:
    """The environment without Slurm job variables (pytest may run in a job)."""
    return {k: v for k, v in os.environ.items() if not k.startswith("SLURM_")}


def start(cmd: list[str], cwd: Path) -> tuple[subprocess.Popen, Path]:
    log = cwd / "run.log"
    with open(log, "w") as out:
        proc = subprocess.Popen(
            cmd, cwd=cwd, stdout=out, stderr=subprocess.STDOUT, env=clean_env(), text=True
        )
    return proc, log


def stop(proc: subprocess.Popen) -> None:
    """Interrupt a run (snakemake then cancels its Slurm jobs), kill if stuck."""
    if proc.poll() is None:
        proc.send_signal(signal.SIGINT)
        try:
            proc.wait(timeout=60)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


def finish(proc: subprocess.Popen, log: Path, what: str) -> str:
    """Wait for a run and return its output; fail if it fails or times out."""
    try:
        proc.wait(timeout=TIMEOUT)
    except subprocess.TimeoutExpired:
        stop(proc)
        pytest.fail(f"{what} run took more than {TIMEOUT:.0f} s:\n{tail(log)}")
    assert proc.returncode == 0, f"{what} run failed (exit {proc.returncode}):\n{tail(log)}"
    return log.read_text(errors="replace")


def tail(log: Path, lines: int = 60) -> str:
    return "\n".join(log.read_text(errors="replace").splitlines()[-lines:])


def is_timing(column: str) -> bool:
    name = column.lower()
    return name in {"cpu_seconds", "wall_seconds"} or "seconds" in name or "time_" in name


def comparable(table: pd.DataFrame) -> pd.DataFrame:
    """The table without timing columns, rows in a canonical order."""
    table = table.drop(columns=[c for c in table.columns if is_timing(str(c))])
    keys = [c for c in table.columns if not pd.api.types.is_float_dtype(table[c])]
    if keys:
        table = table.sort_values(keys, kind="stable")
    return table.reset_index(drop=True)


def assert_same_table(local: pd.DataFrame, slurm: pd.DataFrame) -> None:
    assert list(local.columns) == list(slurm.columns), "the two runs have different columns"
    assert local.shape == slurm.shape, f"shapes differ: {local.shape} vs {slurm.shape}"
    for column in local.columns:
        a, b = local[column], slurm[column]
        assert a.dtype == b.dtype, f"{column}: dtype {a.dtype} vs {b.dtype}"
        if pd.api.types.is_float_dtype(a):
            np.testing.assert_allclose(
                b.to_numpy(), a.to_numpy(), rtol=1e-12, atol=0.0, equal_nan=True,
                err_msg=f"column {column!r} differs",
            )
        else:
            pd.testing.assert_series_equal(a, b, check_exact=True, obj=f"column {column!r}")


def test_slurm_run_matches_local_run(slurm, tmp_path):
    base = Path(os.environ.get("SLURM_TEST_TMPDIR") or tmp_path)
    base.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix="slurm-test-", dir=base))
    local_dir = copy_workflow(work / "local")
    slurm_dir = copy_workflow(work / "slurm")
    assert (slurm_dir / "profiles" / "slurm" / "config.yaml").is_file()

    snakemake = [sys.executable, "-m", "snakemake"]
    extra = shlex.split(os.environ.get("SLURM_TEST_ARGS", ""))
    targets = shlex.split(os.environ.get("SLURM_TEST_TARGETS", ""))
    # targets first: --config takes all following words as its values.
    # Both runs at once: the Slurm one mostly waits for its status polls.
    slurm_run = start(
        snakemake + [*targets, "--profile", "profiles/slurm", *extra, *CONFIG], slurm_dir
    )
    local_run = start(snakemake + [*targets, "--cores", "2", *CONFIG], local_dir)
    try:
        finish(*local_run, "local")
        slurm_log = finish(*slurm_run, "Slurm")
    finally:
        stop(local_run[0])
        stop(slurm_run[0])

    submitted = re.findall(r"submitted with SLURM jobid (\d+)", slurm_log)
    assert submitted, "the Slurm run submitted no job through sbatch:\n" + slurm_log[-3000:]

    local = pd.read_csv(local_dir / TABLE)
    remote = pd.read_csv(slurm_dir / TABLE)
    assert len(local) > 0, f"{TABLE} of the local run is empty"
    assert_same_table(comparable(local), comparable(remote))
    shutil.rmtree(work, ignore_errors=True)
