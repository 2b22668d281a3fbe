"""How the registries find schemes and problems (mcfbench/running/discovery.py): the
folder scan and its order, entry points of installed distributions, a name
declared twice; and, end to end, a scheme of an outside package installed by pip
(``outside_package/``) in ``schemes``, ``run`` and the matrix's plan."""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mcfbench.problems
import mcfbench.schemes
from mcfbench.running import discovery, observers, problems
from mcfbench.running.discovery import RegistryError, discover, package_source
from mcfbench.running.problem import Problem
from mcfbench.running.scheme import Scheme
from mcfbench.running.schemes import SCHEMES

ROOT = Path(__file__).resolve().parents[3]
OUTSIDE = Path(__file__).with_name("outside_package")


def _scheme_module(name, order=None):
    order = "" if order is None else f"ORDER = {order}\n"
    return (f"from mcfbench.running.scheme import Scheme\n{order}"
            f"SCHEME = Scheme({name!r}, {name!r}, 'baselines.cotan:CotanFlow')\n")


def _package(root, name, modules):
    """A package ``name`` under ``root`` with ``{module: source}``; ``root`` on sys.path
    (the caller's monkeypatch)."""
    folder = root / name
    folder.mkdir(parents=True)
    (folder / "__init__.py").write_text("")
    for module, source in modules.items():
        (folder / f"{module}.py").write_text(source)
    return folder


def _distribution(site, dist, version, group, points, package, modules):
    """An installed distribution in ``site``, as pip leaves one: its package and a
    ``.dist-info`` with its metadata and entry points."""
    _package(site, package, modules)
    info = site / f"{dist.replace('-', '_')}-{version}.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n")
    (info / "entry_points.txt").write_text(
        f"[{group}]\n" + "".join(f"{k} = {v}\n" for k, v in points.items()))


def test_a_folder_is_scanned_by_order_then_name(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    folder = _package(tmp_path, "scan_order", {
        "b_first": "from mcfbench.running.scheme import Scheme\nORDER = 1\nSCHEMES = [\n"
                   "    Scheme('s2', 's2', 'm:C'), Scheme('s1', 's1', 'm:C')]\n",
        "a_second": _scheme_module("s3", order=2),
        "zz": _scheme_module("s5"), "aa": _scheme_module("s4")})
    registry, modules = discover([str(folder)], "scan_order", "SCHEME", "SCHEMES", Scheme)
    assert list(registry) == ["s2", "s1", "s3", "s4", "s5"]
    assert [registry[n].module for n in registry] == [
        "scan_order.b_first", "scan_order.b_first", "scan_order.a_second", "scan_order.aa",
        "scan_order.zz"]
    assert {registry[n].source for n in registry} == {None}
    assert modules["s4"].__name__ == "scan_order.aa"


def test_the_builtins_come_in_their_documented_order():
    """mcfbench/schemes/__init__.py: ddfv 10, cotan 20, cmcf 30, bgn 40, bgn_bdf 45,
    mdr 50, dual_mdr 55, deturck 60, kll 70; the problems' modules 1-13, then the real meshes (100)."""
    modules = list(dict.fromkeys(s.module for s in SCHEMES.values()))
    assert modules == [f"mcfbench.schemes.{m}" for m in
                       ("ddfv", "cotan", "cmcf", "bgn", "bgn_bdf", "mdr", "dual_mdr", "deturck",
                        "kll")]
    assert list(SCHEMES)[:2] == ["ddfv", "ddfv-chord"] and list(SCHEMES)[-1] == "kll"
    names = list(problems.PROBLEMS)
    assert names[:8] == ["sphere", "catenoid", "hemisphere", "torus", "dumbbell",
                         "dumbbell_through_pinch", "angenent", "enneper"]
    assert {problems.PROBLEMS[n].module for n in names[14:]} == {"mcfbench.problems.real_meshes"}
    assert all(problems.PROBLEMS[n].module == f"mcfbench.problems.{n}" for n in names[:14])


def test_a_module_that_declares_nothing_is_refused(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    folder = _package(tmp_path, "scan_empty", {"lonely": "ORDER = 1\n",
                                               "wrong": "SCHEME = 'cotan'\n"})
    with pytest.raises(RegistryError, match="scan_empty.lonely: a scheme module defines SCHEME"):
        discover([str(folder)], "scan_empty", "SCHEME", "SCHEMES", Scheme)
    (folder / "lonely.py").unlink()
    with pytest.raises(RegistryError, match="scan_empty.wrong: .* not a Scheme: 'cotan'"):
        discover([str(folder)], "scan_empty", "SCHEME", "SCHEMES", Scheme)


def test_two_modules_declaring_one_name_are_an_error_naming_both(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    folder = _package(tmp_path, "scan_clash", {"one": _scheme_module("twin", 1),
                                               "two": _scheme_module("twin", 2)})
    with pytest.raises(RegistryError, match=r"scheme 'twin' is declared twice: by "
                                            r"scan_clash\.one \(.*one\.py\) and by "
                                            r"scan_clash\.two \(.*two\.py\); rename one"):
        discover([str(folder)], "scan_clash", "SCHEME", "SCHEMES", Scheme)


def test_a_name_is_a_word_for_a_folder(tmp_path):
    for bad in ("a/b", "cotan@bdf2", "", "two words"):
        with pytest.raises(ValueError, match="a name is a non-empty word"):
            Scheme(bad, "x", "m:C")
        with pytest.raises(ValueError, match="a name is a non-empty word"):
            Problem(bad, "x", "sphere", dict, levels=(1,), tau_1=0.1, t_final=0.1, metrics=())
    with pytest.raises(ValueError, match="unknown kind 'smooth'"):
        Problem("p", "x", "sphere", dict, levels=(1,), tau_1=0.1, t_final=0.1, metrics=(),
                kind="smooth")


def test_an_installed_scheme_joins_after_the_builtins_with_its_source(tmp_path, monkeypatch):
    site = tmp_path / "site"
    _distribution(site, "mcf-extra", "1.2.0", "mcfbench.schemes",
                  {"extra": "extra_schemes.declared:SCHEMES"}, "extra_schemes",
                  {"declared": "from mcfbench.running.scheme import Scheme\nSCHEMES = [\n"
                               "    Scheme('extra-b', 'b', 'extra_schemes.declared:C'),\n"
                               "    Scheme('extra-a', 'a', 'extra_schemes.declared:C')]\n"})
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.delitem(sys.modules, "extra_schemes", raising=False)
    registry, _ = discover(mcfbench.schemes.__path__, "mcfbench.schemes", "SCHEME", "SCHEMES",
                           Scheme, "mcfbench.schemes")
    assert list(registry) == [*SCHEMES, "extra-b", "extra-a"]
    source = registry["extra-a"].source
    assert registry["extra-a"].module == "extra_schemes.declared"
    assert (source["distribution"], source["version"]) == ("mcf-extra", "1.2.0")
    assert len(source["files_sha256"]) == 64
    # an edit of the package's files (an editable install's) changes its identity
    (site / "extra_schemes" / "declared.py").write_text(
        (site / "extra_schemes" / "declared.py").read_text() + "# edited\n")
    assert package_source("extra_schemes.declared", None)["files_sha256"] != \
        source["files_sha256"]


def test_an_installed_scheme_with_a_builtin_name_is_refused_naming_both(tmp_path, monkeypatch):
    site = tmp_path / "site"
    _distribution(site, "mcf-rival", "0.1", "mcfbench.schemes",
                  {"rival": "rival_schemes:SCHEME"}, "rival_schemes", {})
    (site / "rival_schemes" / "__init__.py").write_text(_scheme_module("cotan"))
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(RegistryError, match=(
            r"scheme 'cotan' is declared twice: by mcfbench\.schemes\.cotan \(.*cotan\.py\) "
            r"and by entry point 'rival' = 'rival_schemes:SCHEME' of mcf-rival 0\.1")):
        discover(mcfbench.schemes.__path__, "mcfbench.schemes", "SCHEME", "SCHEMES", Scheme,
                 "mcfbench.schemes")


def test_an_entry_point_that_loads_no_scheme_is_named(tmp_path, monkeypatch):
    site = tmp_path / "site"
    _distribution(site, "mcf-broken", "2.0", "mcfbench.schemes",
                  {"broken": "broken_schemes:NOTHING", "text": "broken_schemes:TEXT"},
                  "broken_schemes", {})
    (site / "broken_schemes" / "__init__.py").write_text("TEXT = 'cotan'\n")
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(RegistryError, match="entry point 'broken' = 'broken_schemes:NOTHING' "
                                            "of mcf-broken 2.0 does not load: AttributeError"):
        discovery.entry_point_items("mcfbench.schemes", Scheme)


def test_an_installed_problem_brings_its_observer(tmp_path, monkeypatch):
    site = tmp_path / "site"
    _distribution(site, "mcf-problem", "0.2", "mcfbench.problems",
                  {"ring": "ring_problem:PROBLEM"}, "ring_problem", {})
    (site / "ring_problem" / "__init__.py").write_text(
        "from mcfbench.running.problem import Problem\n"
        "class Count:\n    def __init__(self, problem): self.n = 0\n"
        "    def __call__(self, flow): self.n += 1\n"
        "    def result(self): return {'states': self.n}\n"
        "METRICS = {'count': Count}\n"
        "PROBLEM = Problem('ring', 'ring', 'torus', dict, levels=(1,), tau_1=0.1, t_final=0.1,"
        " metrics=('count',), kind='reference', data_files=('ring.json',))\n")
    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(observers, "METRICS", dict(observers.METRICS))
    registry = dict(problems.PROBLEMS)
    assert problems.discover_problems([], "none", problems.GROUP, registry) == ["ring"]
    ring = registry["ring"]
    assert ring.source["distribution"] == "mcf-problem" and ring.module == "ring_problem"
    assert ring.data_files == (Path("ring.json"),) and ring.kind == "reference"
    assert type(ring.observers()[0]).__name__ == "Count"


# -- end to end: pip installs the outside package -------------------------------------


def _python(args, site, cwd, check=True):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    result = subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env,
                            cwd=cwd, timeout=600)
    if check:
        assert result.returncode == 0, result.stderr
    return result


def _pip_install(source, site):
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "--no-index",
                    "--no-build-isolation", "--target", str(site), str(source)],
                   check=True, capture_output=True, text=True, timeout=600)


@pytest.mark.e2e
def test_a_scheme_of_an_installed_package_runs_without_an_edit_here(tmp_path):
    """pip installs ``outside_package`` (its own pyproject.toml, a flow class of its own,
    an entry point in ``mcfbench.schemes``) into a folder on PYTHONPATH: its scheme is
    listed, runs on a committed mesh as the exact sphere's flow does, and the matrix
    plans and runs it (Snakemake, no file of this repository edited); a second package declaring ``cotan`` stops the registry, naming both."""
    source, site = tmp_path / "pkg", tmp_path / "site"
    shutil.copytree(OUTSIDE, source)
    _pip_install(source, site)
    assert (site / "mcf_plugin-0.3.1.dist-info" / "entry_points.txt").is_file()

    listed = _python(["-m", "mcfbench", "schemes"], site, tmp_path).stdout.split("\n\n")[0]
    listed = listed.splitlines()            # the registry's lines, before the suffixes' note
    assert listed[-1].split()[0] == "cotan-consistent" and listed[-1].endswith(
        "[mcf-plugin 0.3.1]")
    assert [line.split()[0] for line in listed[:-1]] == list(SCHEMES)

    mesh = ROOT / "mcfbench" / "data" / "meshes" / "noisy_sphere.obj"
    _python(["-m", "mcfbench", "run", str(mesh), "--scheme", "cotan-consistent",
             "--tau-edge", "0.1", "--steps", "5", "--out", "run.npz"], site, tmp_path)
    with np.load(tmp_path / "run.npz", allow_pickle=True) as run:
        assert str(run["status"]) == "ok" and str(run["scheme"]) == "cotan-consistent"
        radius, t = np.linalg.norm(run["vertices"], axis=2).mean(axis=1), run["t"]
    # a sphere's radius sqrt(R^2 - 4t) (the noisy unit sphere, 5 steps to t = 0.0176)
    assert t[-1] > 0.017 and np.abs(radius - np.sqrt(radius[0] ** 2 - 4 * t)).max() < 1e-3

    planned = _python(["-c", "import json; from mcfbench.studies.matrix.plan import plan; "
                       "p = plan({'select': {'schemes': ['cotan-consistent', 'cotan'], "
                       "'problems': {'sphere': [1]}}}); "
                       "print(json.dumps([p['schemes'], p['problems']]))"], site, tmp_path)
    assert json.loads(planned.stdout) == [["cotan-consistent", "cotan"], {"sphere": [1]}]

    # and the matrix runs it: Snakemake in a copy of the workflow, the package on PYTHONPATH
    work = tmp_path / "work"
    work.mkdir()
    shutil.copy2(ROOT / "Snakefile", work / "Snakefile")
    for name in ("workflow", "config"):
        shutil.copytree(ROOT / name, work / name,
                        ignore=shutil.ignore_patterns(".snakemake", "__pycache__"))
    _python(["-m", "snakemake", "--cores", "2", "matrix", "--config",
             "matrix={select: {schemes: [cotan-consistent, cotan], problems: {sphere: [1]}}}"],
            site, work)
    import pandas as pd

    summary = pd.read_csv(work / "results" / "matrix" / "tables" / "summary.csv")
    row = summary[summary["scheme"] == "cotan-consistent"].iloc[0]
    assert row["status"] == "ok" and row["runs_ok"] == 1

    rival = tmp_path / "rival"
    shutil.copytree(OUTSIDE, rival)
    for path, old, new in ((rival / "pyproject.toml", 'name = "mcf-plugin"', 'name = "rival"'),
                           (rival / "pyproject.toml", "cotan-consistent =", "rival ="),
                           (rival / "mcfplugin" / "schemes.py", '"cotan-consistent"', '"cotan"')):
        path.write_text(path.read_text().replace(old, new))
    (rival / "mcfplugin").rename(rival / "rivalplugin")
    for path in (rival / "pyproject.toml", rival / "rivalplugin" / "schemes.py"):
        path.write_text(path.read_text().replace("mcfplugin", "rivalplugin"))
    _pip_install(rival, site)
    refused = _python(["-m", "mcfbench", "schemes"], site, tmp_path, check=False)
    assert refused.returncode != 0
    assert ("scheme 'cotan' is declared twice: by mcfbench.schemes.cotan (" in refused.stderr
            and "and by entry point 'rival' = 'rivalplugin.schemes:SCHEMES' of rival 0.3.1"
            in refused.stderr)
