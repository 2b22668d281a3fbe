"""Imports flow one way: workflow -> mcfbench -> {ddfv, baselines} -> kept_factor.

The scheme packages import neither the harness nor each other; what they
share (the kept factorisation of a sequence of nearby sparse systems) is
``kept_factor``, which imports numpy, scipy and cholespy only (and numba, for
``kept_factor.threads``). ``import
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
    """And numba in its thread helper (kept_factor/threads.py) only."""
    imported = {str(path.relative_to(ROOT)): sorted(_imported_tops(path))
                for path in sorted((ROOT / "kept_factor").rglob("*.py"))}
    allowed = {"numpy", "scipy", "cholespy"} | sys.stdlib_module_names
    assert imported and all(set(names) <= allowed | ({"numba"} if path.endswith("threads.py")
                                                     else set())
                            for path, names in imported.items()), imported


@pytest.mark.parametrize("package", sorted(FORBIDDEN))
def test_importing_a_scheme_package_loads_nothing_of_the_others(package):
    code = (f"import sys, {package}\n"
            f"bad = sorted(m for m in sys.modules if m.split('.')[0] in {FORBIDDEN[package]!r})\n"
            "print(','.join(bad))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, check=True).stdout.strip()
    assert out == ""


def test_a_vertex_scheme_s_run_loads_no_ddfv_kernel():
    """The shared solver checks threads with kept_factor.threads, not with ddfv, whose
    kernels' import loads every DDFV kernel from numba's cache: a cotan job does not
    pay it."""
    code = ("import sys\nfrom mcfbench.running.run import run\n"
            "run('cotan', 'sphere', 1)\n"
            "print('ddfv.kernels' in sys.modules, 'kept_factor.threads' in sys.modules)")
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


PACKAGES = ("mcfbench", "ddfv", "baselines", "kept_factor")


def _module_name(path):
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _import_graph():
    """Module -> the modules of :data:`PACKAGES` it imports, anywhere in its source
    (a function's lazy import too: it closes a loop as soon as it runs). ``from a
    import b`` names the module ``a.b`` when there is one, else ``a``."""
    paths = {_module_name(p): p for package in PACKAGES for p in (ROOT / package).rglob("*.py")}
    graph = {}
    for name, path in paths.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        targets = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                targets.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")[:len(package.split(".")) - node.level + 1]
                    base = ".".join(anchor + ([base] if base else []))
                targets.update(f"{base}.{a.name}" if f"{base}.{a.name}" in paths else base
                               for a in node.names)
        graph[name] = {t for t in targets if t in paths and t != name}
    return graph


def _cycles(graph):
    """The strongly connected components of more than one module (Tarjan), each as a
    sorted tuple of names."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(tuple(sorted(component)))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return set(found)


def test_the_cycle_finder_finds_a_loop_and_only_loops():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}, "e": set()}
    assert _cycles(graph) == {("a", "b", "c")}
    assert _cycles({"a": {"b"}, "b": set()}) == set()


def test_the_modules_import_each_other_without_a_loop():
    """No module imports (even lazily) a module that imports it back, through any chain
    (issue #43 found three: the convergence and beyond plans, the problem registry and
    the real meshes' problems, the Angenent torus and the meridian solver)."""
    graph = _import_graph()
    assert _cycles(graph) == set()
