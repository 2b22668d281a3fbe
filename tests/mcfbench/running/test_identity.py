"""A run's code identity (mcfbench/running/identity.py): which code is in which run's."""

import json
import os
import shutil
import subprocess
import sys

import pytest

from mcfbench.running import identity
from mcfbench.running.identity import (
    HARNESS,
    STOP,
    identity_digest,
    problem_data,
    run_identity,
)
from mcfbench.running.problems import PROBLEMS, get_problem
from mcfbench.running.schemes import SCHEMES
from mcfbench.storage import code_identity as ci

VARIANTS = [*SCHEMES, *(f"{s}@bdf2" for s, e in SCHEMES.items() if not e.integrates_itself)]
BGN_FAMILY = {"bgn", "bgn-bdf2", "bgn-bdf3", "mdr", "dual-mdr", "deturck", "kll"}
"""The baselines that import baselines/bgn.py (bgn_bdf, mdr; dual-mdr, deturck and kll
through mdr)."""


@pytest.fixture
def fresh():
    """Identities recomputed before and after (a test that patches what they read)."""
    identity.forget_identities()
    yield
    identity.forget_identities()


def _modules(scheme, problem="sphere"):
    return set(run_identity(scheme, problem)["modules"])


def test_no_presentation_module_is_in_any_run_s_identity():
    presenting = ("mcfbench/presentation/", "mcfbench/studies/", "mcfbench/cli.py",
                  "mcfbench/pipeline.py", "mcfbench/__main__.py")
    for problem in ("sphere", "dumbbell", "real_nut"):
        for scheme in VARIANTS:
            found = [m for m in _modules(scheme, problem) if m.startswith(presenting)]
            assert found == [], (scheme, problem, found)


def test_bgn_is_in_the_identity_of_the_schemes_that_import_it_only():
    for scheme in VARIANTS:
        base = scheme.partition("@")[0]
        assert ("baselines/bgn.py" in _modules(scheme)) == (base in BGN_FAMILY), scheme


def test_ddfv_modules_are_in_ddfv_runs_only():
    """The shared solver's thread helper is kept_factor/threads.py, in every run's
    identity; every ddfv module in the DDFV runs' only."""
    for scheme in VARIANTS:
        ddfv = {m for m in _modules(scheme) if m.startswith("ddfv/")}
        if SCHEMES[scheme.partition("@")[0]].family == "ddfv":
            assert {"ddfv/flow.py", "ddfv/assembly.py", "ddfv/kernels.py"} <= ddfv, scheme
        else:
            assert ddfv == set(), scheme
        assert "kept_factor/threads.py" in _modules(scheme), scheme


def test_a_scheme_s_identity_is_its_own_modules_and_the_shared_ones():
    """cotan and its Voronoi variant share their modules and differ by their
    entries' options, which are part of the identity as values (a label is not);
    cotan-intrinsic's has its own module and robust-laplacian, not cotan's; an
    integrator other than Euler adds only its module (shared)."""
    digests = {s: identity_digest(run_identity(s, "sphere")) for s in VARIANTS}
    assert _modules("cotan") == _modules("cotan-voronoi") == _modules("cotan-redistribute")
    assert _modules("ddfv") == _modules("ddfv-chord-carried")
    assert len({digests[s] for s in ("cotan", "cotan-voronoi", "cotan-redistribute")}) == 3
    assert run_identity("cotan-voronoi", "sphere")["scheme"] == {
        "flow": "baselines.cotan:CotanFlow", "options": {"mass": "voronoi"},
        "integrator": "euler"}
    assert len({digests[s] for s in ("cotan", "cotan-intrinsic", "cmcf", "bgn", "mdr",
                                      "deturck", "kll", "ddfv")}) == 8
    intrinsic = run_identity("cotan-intrinsic", "sphere")
    assert "baselines/cotan_intrinsic.py" in intrinsic["modules"]
    assert "baselines/cotan.py" not in intrinsic["modules"]
    assert "robust-laplacian" in intrinsic["distributions"]
    assert "robust-laplacian" not in run_identity("cotan", "sphere")["distributions"]
    assert _modules("bgn@bdf2") == _modules("bgn")


def test_a_surgery_scheme_s_identity_has_the_surgery_modules_and_its_name(fresh,
                                                                           monkeypatch):
    """NAME+surgery: the neck's cut and the continuation are in its identity (as roots
    of their own, whether or not the harness reaches them), and its scheme values say
    so; cut out of the harness's closure, they stay in the surgery run's alone."""
    for scheme in ("cotan+surgery", "ddfv-chord-carried+surgery", "bgn+surgery"):
        modules = _modules(scheme, "dumbbell")
        assert {"mcfbench/geometry/mesh_surgery.py", "mcfbench/running/continuation.py",
                "mcfbench/geometry/reextraction.py", "mcfbench/running/surgery.py",
                "mcfbench/geometry/remeshing.py"} <= modules
        assert run_identity(scheme, "dumbbell")["scheme"]["mesh_strategy"] == "surgery"
    assert "mesh_strategy" not in run_identity("cotan", "dumbbell")["scheme"]
    assert identity_digest(run_identity("cotan+surgery", "dumbbell")) != \
        identity_digest(run_identity("cotan", "dumbbell"))
    identity.forget_identities()
    monkeypatch.setattr(identity, "HARNESS", ())
    assert "mcfbench/geometry/mesh_surgery.py" in _modules("cotan+surgery", "dumbbell")
    assert "mcfbench/geometry/mesh_surgery.py" not in _modules("cotan", "dumbbell")
    assert "mcfbench/geometry/reextraction.py" not in _modules("cotan", "dumbbell")


def test_the_registries_are_not_followed_from_the_harness():
    """From the harness's roots no scheme is reached through the scheme registry,
    which the harness imports (without the stop rule it would be in every run's
    identity: a new scheme would rerun every run)."""
    modules, _ = ci.closure(HARNESS, ci.REPOSITORY_PACKAGES, STOP)
    assert "mcfbench.running.schemes" not in modules
    assert not any(m.startswith("baselines") for m in modules)
    unstopped, _ = ci.closure(HARNESS, ci.REPOSITORY_PACKAGES)
    assert "mcfbench.running.schemes" in unstopped
    assert not any("mcfbench/running/schemes.py" in _modules(s) for s in VARIANTS)


def test_a_changed_data_file_changes_its_real_mesh_problem_s_identity_only(fresh,
                                                                         monkeypatch):
    """The committed real mesh's files are in its problem's identity; a change of
    nut's reference file (its hash patched) changes real_nut's identity alone."""
    files = {p.name for p in problem_data(get_problem("real_nut"))}
    assert files == {"nut.ply", "nut.json", "nut.npz"}
    assert problem_data(get_problem("sphere")) == ()
    before = {p: identity_digest(run_identity("cotan", p)) for p in PROBLEMS}
    real = ci.file_hash
    identity.forget_identities()
    with monkeypatch.context() as patch:
        patch.setattr(ci, "file_hash",
                      lambda path: "changed" if str(path).endswith("/nut.json") else real(path))
        after = {p: identity_digest(run_identity("cotan", p)) for p in PROBLEMS}
    assert {p for p in PROBLEMS if before[p] != after[p]} == {"real_nut"}


def test_a_changed_dependency_version_changes_the_identity_of_who_imports_it(fresh,
                                                                            monkeypatch):
    before = {s: identity_digest(run_identity(s, "sphere")) for s in SCHEMES}
    real = ci.distribution_version
    identity.forget_identities()
    with monkeypatch.context() as patch:
        patch.setattr(ci, "distribution_version",
                      lambda name: "9.9.9" if name == "robust-laplacian" else real(name))
        after = {s: identity_digest(run_identity(s, "sphere")) for s in SCHEMES}
    assert {s for s in SCHEMES if before[s] != after[s]} == {"cotan-intrinsic"}


def test_the_identities_of_a_full_matrix_cost_well_under_a_second(fresh):
    """Every scheme (Euler and BDF2) on every problem, from a cold cache: the
    files read once, each run's identity then a lookup (measured 0.45-0.65 CPU s
    under load 15; the bound is a guard against a closure recomputed per run,
    which costs minutes, not a benchmark: CPU time, three times the measured)."""
    import time

    start = time.process_time()
    digests = {(s, p): identity_digest(run_identity(s, p)) for s in VARIANTS for p in PROBLEMS}
    assert len(digests) == len(VARIANTS) * len(PROBLEMS)
    assert time.process_time() - start < 2.0


def test_one_changed_line_of_bgn_changes_the_identity_of_bgn_s_family_only(tmp_path):
    """An honest edit: the repository copied, one line of baselines/bgn.py changed,
    the identities recomputed by a process that imports the copy."""
    root = ci.package_folder("mcfbench")
    for package in ci.REPOSITORY_PACKAGES:
        shutil.copytree(root / package, tmp_path / package,
                        ignore=shutil.ignore_patterns("__pycache__"))
    bgn = tmp_path / "baselines" / "bgn.py"
    lines = bgn.read_text().splitlines(keepends=True)
    lines[0] = lines[0].rstrip("\n") + " (edited)\n"
    bgn.write_text("".join(lines))
    code = ("import json\n"
            "from mcfbench.running.identity import identity_digest, run_identity\n"
            "from mcfbench.storage.code_identity import package_folder\n"
            f"names = {VARIANTS!r}\n"
            "print(json.dumps({'root': str(package_folder('mcfbench')), 'digests': "
            "{s: identity_digest(run_identity(s, 'sphere')) for s in names}}))\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(tmp_path), *filter(None, [os.environ.get("PYTHONPATH")])])}
    out = json.loads(subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path,
                                    capture_output=True, text=True, check=True).stdout)
    assert out["root"] == str(tmp_path)
    before = {s: identity_digest(run_identity(s, "sphere")) for s in VARIANTS}
    changed = {s for s in VARIANTS if out["digests"][s] != before[s]}
    assert changed == {s for s in VARIANTS if s.partition("@")[0] in BGN_FAMILY}


def test_the_registry_s_identity_is_the_union_of_every_run_s(fresh, monkeypatch):
    """A change that reaches one run only (nut's reference file) changes the
    registry's digest too; one that reaches none (a presentation module) does not."""
    before = identity.registry_identity()
    real = ci.file_hash
    identity.forget_identities()
    with monkeypatch.context() as patch:
        patch.setattr(ci, "file_hash", lambda path: "changed" if str(path).endswith(
            ("/nut.json", "/presentation/formats.py")) else real(path))
        changed = identity.registry_identity()
        patch.setattr(ci, "file_hash", lambda path: "changed" if str(path).endswith(
            "/presentation/formats.py") else real(path))
        identity.forget_identities()
        unchanged = identity.registry_identity()
    assert changed != before and unchanged == before


def test_a_user_mesh_run_s_identity_is_its_scheme_s_and_the_problem_definitions(fresh):
    """The gallery's runs (problem ``gallery``, a user's mesh file whose SHA-256 is in
    the spec): the scheme's modules and the problem definitions', no registry problem's
    module or data; a scheme's edit changes it as it changes the scheme's other runs."""
    gallery, sphere = run_identity("cotan", "gallery"), run_identity("cotan", "sphere")
    assert gallery["data"] == {}
    assert "mcfbench/problems/sphere.py" in sphere["modules"]
    assert not any(m.startswith("mcfbench/problems/") for m in gallery["modules"])
    assert {"mcfbench/running/problem.py", "baselines/cotan.py"} <= set(gallery["modules"])
    assert "baselines/bgn.py" not in gallery["modules"]


def test_the_jobs_import_the_packages_the_workflow_planned_with_first():
    """The Snakefile's ``PYTHONPATH`` for the jobs: the folder of the ``mcfbench`` whose
    digests the batches' params carry, then the rest, that folder once."""
    import mcfbench
    from mcfbench.pipeline import jobs_pythonpath

    root = os.path.dirname(os.path.dirname(os.path.realpath(mcfbench.__file__)))
    assert jobs_pythonpath(None) == root
    assert jobs_pythonpath(os.pathsep.join(["/elsewhere", root, ""])) == \
        os.pathsep.join([root, "/elsewhere"])
