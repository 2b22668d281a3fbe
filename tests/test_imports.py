"""Imports flow one way: workflow -> mcfbench -> {ddfv, baselines} -> kept_factor.

The scheme packages import neither the harness nor each other; what they
share (the kept factorisation of a sequence of nearby sparse systems) is
``kept_factor``, which imports numpy, scipy and cholespy only. ``import
ddfv`` changes nothing process-wide (no malloc tuning, no threads).
"""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
FORBIDDEN = {"ddfv": ("mcfbench", "baselines"), "baselines": ("mcfbench", "ddfv"),
             "kept_factor": ("mcfbench", "ddfv", "baselines")}


def _imported_tops(path):
    """Top-level package names imported anywhere in a source file."""
    tree = ast.parse(path.read_text())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.split(".")[0])
    return names


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_scheme_packages_do_not_import_the_harness_or_each_other(package):
    offending = {}
    for path in sorted((ROOT / package).rglob("*.py")):
        bad = _imported_tops(path) & set(FORBIDDEN[package])
        if bad:
            offending[str(path.relative_to(ROOT))] = sorted(bad)
    assert offending == {}


def test_kept_factor_imports_numpy_scipy_and_cholespy_only():
    imported = {str(path.relative_to(ROOT)): sorted(_imported_tops(path))
                for path in sorted((ROOT / "kept_factor").rglob("*.py"))}
    assert imported and all(set(names) <= {"numpy", "scipy", "cholespy"}
                            for names in imported.values()), imported


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_importing_a_scheme_package_loads_nothing_of_the_others(package):
    code = (f"import sys, {package}\n"
            f"bad = sorted(m for m in sys.modules if m.split('.')[0] in {FORBIDDEN[package]!r})\n"
            "print(','.join(bad))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout.strip()
    assert out == ""


def test_a_vertex_scheme_s_run_loads_no_ddfv_kernel():
    """The shared solver checks threads with ddfv.threads, not ddfv.kernels, whose
    import loads every DDFV kernel from numba's cache: a cotan job does not pay it."""
    code = ("import sys\nfrom mcfbench.running.run import run\n"
            "run('cotan', 'sphere', 1)\n"
            "print('ddfv.kernels' in sys.modules, 'ddfv.threads' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout.split()
    assert out == ["False", "True"]


def test_import_ddfv_has_no_process_wide_side_effect():
    """The glibc malloc tuning is an explicit call of the entry points."""
    code = ("import sys, ddfv\n"
            "print('mcfbench.storage.memory' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout.strip()
    assert out == "False"
    assert "tune_malloc" not in (ROOT / "ddfv" / "__init__.py").read_text()
