"""The harness's layout: layers import one way, modules stay small, names are unique.

Rules (``mcfbench/<layer>/__init__.py`` states each in one sentence):
``storage`` imports no other layer; ``geometry`` imports ``storage`` at most;
``running`` never ``presentation`` or ``studies``; ``presentation`` never
``studies`` and of ``running`` only the registries (declarative: names,
labels, styles, metrics); and importing any presentation module loads no solver, driver,
flow, compiled kernel or numba.

A study is one folder, ``mcfbench/studies/<study>/``, its modules named by their
role: ``plan`` and ``job`` may run schemes (any module of the harness); every other
module of the folder (``tables``, ``findings``, ``plots``, ``page``, ...) presents,
under the presentation rule, and may import the presentation modules of the studies
(Table 3.1's tables serve the beyond study's) and a study's ``__init__`` (its paths);
``aggregate`` may read its study's plan, and loads no solver when imported either.
"""

import ast
import subprocess
import sys
from collections import defaultdict
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HARNESS = ROOT / "mcfbench"
LAYERS = ("storage", "geometry", "running", "schemes", "problems", "presentation", "studies")
# layer -> the mcfbench modules (prefixes) it may import
ALLOWED = {
    "storage": ("mcfbench.storage",),
    "geometry": ("mcfbench.storage", "mcfbench.geometry"),
    "running": ("mcfbench.storage", "mcfbench.geometry", "mcfbench.running", "mcfbench.schemes",
                "mcfbench.problems"),
    # a scheme module: the class it declares, never the registry (which imports it)
    "schemes": ("mcfbench.running.scheme", "mcfbench.schemes"),
    # a problem module: the class, the observers, the real meshes' generator
    "problems": ("mcfbench.storage", "mcfbench.geometry", "mcfbench.running.problem",
                 "mcfbench.running.observers", "mcfbench.running.real_mesh_problems",
                 "mcfbench.problems"),
    "presentation": ("mcfbench.storage", "mcfbench.geometry", "mcfbench.presentation",
                     "mcfbench.running.schemes", "mcfbench.running.problems",
                     "mcfbench.running.integrators"),
    "studies": ("mcfbench",),
}
RUNNING_ROLES = ("plan", "job")
"""The modules of a study folder that may run schemes; the others present."""
STUDIES = sorted(p.name for p in (HARNESS / "studies").iterdir()
                 if (p / "__init__.py").exists())
MAX_LINES = 600


def _modules():
    return sorted(p for p in HARNESS.rglob("*.py"))


def _study_modules(roles):
    """``(path, dotted name)`` of the modules of every study folder whose role is
    in ``roles`` (``"presentation"``: every role but :data:`RUNNING_ROLES`)."""
    found = []
    for study in STUDIES:
        for path in sorted((HARNESS / "studies" / study).glob("*.py")):
            role = path.stem
            if (role in roles) or (roles == "presentation" and role not in RUNNING_ROLES
                                   and role != "aggregate"):
                name = f"mcfbench.studies.{study}" + ("" if role == "__init__" else f".{role}")
                found.append((path, name))
    return found


def _allowed(name, allowed):
    return any(name == a or name.startswith(a.rstrip(".") + ".") for a in allowed)


def _imports(path):
    """Every module imported anywhere in a file (function-level imports too)."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            assert node.level == 0, f"{path}: relative import (the harness imports absolutely)"
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


@pytest.mark.parametrize("layer", LAYERS)
def test_each_layer_imports_only_the_layers_below(layer):
    offending = {}
    for path in sorted((HARNESS / layer).rglob("*.py")):
        bad = sorted(n for n in _imports(path) if n.startswith("mcfbench.")
                     and not any(n == a or n.startswith(a.rstrip(".") + ".") for a in ALLOWED[layer]))
        if bad:
            offending[str(path.relative_to(ROOT))] = bad
    assert offending == {}


def test_the_presentation_modules_of_a_study_import_no_running_module():
    """``tables``, ``findings``, ``plots``, ``page`` (every role but plan and job) of
    every study folder: the presentation rule, plus the presentation modules of the
    studies and the studies' ``__init__`` (paths, declarations)."""
    presentation = {name for _, name in _study_modules("presentation")}
    offending = {}
    for path, _ in _study_modules("presentation"):
        bad = sorted(n for n in _imports(path) if n.startswith("mcfbench.")
                     and not _allowed(n, ALLOWED["presentation"])
                     and n not in presentation and n.rsplit(".", 1)[0] not in presentation)
        if bad:
            offending[str(path.relative_to(ROOT))] = bad
    assert offending == {}


def test_every_study_is_one_folder_of_role_modules():
    assert set(STUDIES) >= {"convergence", "beyond", "figures", "matrix", "gallery", "report"}
    assert sorted(p.name for p in (HARNESS / "studies").glob("*.py")) == ["__init__.py",
                                                                          "config.py"]


def _loaded(modules, matches):
    """The modules, sorted and joined by commas, that a fresh interpreter holds after
    importing ``modules`` and whose name ``m`` makes the expression ``matches`` true."""
    code = (f"import sys\nfor m in {modules!r}: __import__(m)\n"
            f"print(','.join(sorted(m for m in sys.modules if {matches})))")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, check=True).stdout.strip()


def test_importing_presentation_loads_no_solver_driver_or_numba():
    modules = sorted(f"mcfbench.presentation.{p.stem}" for p in (HARNESS / "presentation").glob("*.py")
                     if p.stem != "__init__")
    modules += [name for _, name in _study_modules(("aggregate",)) + _study_modules("presentation")]
    assert _loaded(modules, "m == 'numba' or m.startswith(('mcfbench.running.solver', "
                            "'mcfbench.running.driver', 'mcfbench.running.run', 'ddfv.kernels', "
                            "'ddfv.flow', 'baselines')) or m.endswith('.job')") == ""


def test_storage_loads_nothing_of_the_other_layers():
    modules = ["mcfbench.storage.records", "mcfbench.storage.atomic", "mcfbench.storage.provenance",
               "mcfbench.storage.run_store"]
    assert _loaded(modules, "m.startswith(('mcfbench.running', 'mcfbench.geometry', "
                            "'mcfbench.presentation', 'mcfbench.studies', 'numba', 'ddfv', "
                            "'baselines'))") == ""


def test_no_harness_module_is_over_600_lines():
    long = {str(p.relative_to(ROOT)): n for p in _modules()
            if (n := len(p.read_text().splitlines())) > MAX_LINES}
    assert long == {}


# every study module defines these (the study protocol); no other name may repeat
PROTOCOL = {"plan", "run_specs", "job", "aggregate", "findings", "from_config"}


def test_no_class_or_public_function_is_defined_twice():
    where = defaultdict(list)
    for path in _modules():
        protocol = PROTOCOL if path.parent.parent.name == "studies" else set()
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)) and not node.name.startswith("_") \
                    and node.name not in protocol:
                where[node.name].append(str(path.relative_to(ROOT)))
    assert {name: paths for name, paths in where.items() if len(paths) > 1} == {}


def test_no_private_name_is_used_outside_its_module():
    offending = []
    for path in _modules():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("mcfbench"):
                offending += [f"{path.relative_to(ROOT)}: {node.module}.{a.name}"
                              for a in node.names if a.name.startswith("_")]
    assert offending == []


def test_every_name_the_workflow_scripts_and_benchmarks_import_exists():
    """The scripts run only inside Snakemake jobs or by hand: a name moved in the
    harness must not leave one of them importing what is no longer there."""
    import importlib

    missing = []
    for path in sorted((ROOT / "workflow" / "scripts").glob("*.py")) + \
            sorted((ROOT / "benchmarks").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom) and node.module and \
                    node.module.split(".")[0] in ("mcfbench", "ddfv", "baselines", "kept_factor"):
                module = importlib.import_module(node.module)
                missing += [f"{path.relative_to(ROOT)}: {node.module}.{a.name}"
                            for a in node.names if not hasattr(module, a.name)
                            and importlib.util.find_spec(f"{node.module}.{a.name}") is None]
    assert missing == []


TESTS = ROOT / "tests" / "mcfbench"
CROSS_CUTTING = {
    "running/test_run_properties.py": "run() of every scheme on random surfaces (hypothesis)",
    "running/test_progress.py": "the progress bars of driver.simulate and run.level_sweep",
    "running/test_reference_metrics.py": "the problems' reference answers",
    "test_layout.py": "the harness's layers and this layout",
}
"""Test files of tests/mcfbench/ that test several modules, each under a name that
says what (docs/tests.md)."""


def _tested_module(rel):
    """The module (or study package) that the test file ``rel`` (relative to
    tests/mcfbench/) is named after, or None: ``<layer>/test_<module>.py`` ->
    ``mcfbench/<layer>/<module>.py``; in a study's folder also ``test_<study>.py`` (the
    study's package) and ``test_<study>_<module>.py`` (basenames are unique in tests/)."""
    folder, name = HARNESS / rel.parent, rel.stem[len("test_"):]
    candidates = [folder / f"{name}.py"]
    if rel.parts[0] == "studies" and len(rel.parts) == 3:
        study = rel.parent.name
        candidates.append(folder / "__init__.py" if name == study else
                          folder / f"{name.removeprefix(study + '_')}.py")
    return next((c for c in candidates if c.is_file()), None)


def test_every_test_file_is_named_after_a_module_of_its_folder():
    """Tests mirror the harness's modules: tests/mcfbench/<layer>/test_<module>.py."""
    files = sorted(p.relative_to(TESTS) for p in TESTS.rglob("test_*.py"))
    assert len(files) > 40 and {str(f) for f in files} >= set(CROSS_CUTTING)
    unnamed = [str(f) for f in files
               if str(f) not in CROSS_CUTTING and _tested_module(f) is None]
    assert unnamed == []
    assert _tested_module(Path("running/test_run.py")) == HARNESS / "running" / "run.py"
    assert _tested_module(Path("studies/matrix/test_matrix_page.py")) == \
        HARNESS / "studies" / "matrix" / "page.py"
    assert _tested_module(Path("running/test_bad_input.py")) is None
