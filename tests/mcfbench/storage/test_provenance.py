"""Provenance (mcfbench/storage/provenance.py): the code is identified from anywhere."""

import json
import subprocess
import sys
from pathlib import Path

from mcfbench.storage.provenance import (
    config_hash,
    dependency_versions,
    provenance,
    source_hash,
)

ROOT = Path(__file__).resolve().parents[3]


def test_provenance_names_code_dependencies_and_settings():
    p = provenance({"level": 3})
    assert p["config"] == {"level": 3} and p["config_hash"] == config_hash({"level": 3})
    assert set(p["source_hash"]) == {"ddfv", "baselines", "kept_factor", "mcfbench"}
    assert all(len(h) == 16 for h in p["source_hash"].values())
    for name in ("numpy", "scipy", "libigl", "snakemake", "numba"):
        assert name in p["packages"], name
    assert p["packages"] == dependency_versions()


def test_dependency_versions_agree_with_importlib_metadata():
    """Read from the metadata headers only: the versions of importlib.metadata's full
    parse, the project and its requirements (and theirs) included."""
    from importlib import metadata

    versions = dependency_versions()
    assert {name: metadata.version(name) for name in versions} == versions
    for name in ("ddfv-mcf", "numpy", "scipy", "numba", "meshio", "jinja2", "markupsafe"):
        assert versions[name] == metadata.version(name), name


def test_git_commit_is_found_from_outside_the_repository(tmp_path):
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True)
    code = "import json; from mcfbench.storage.provenance import provenance; " \
           "print(json.dumps(provenance({})))"
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True).stdout
    p = json.loads(out)
    assert commit.returncode == 0       # the tests run from a checkout (CI's clone is one)
    assert p["git_commit"] == commit.stdout.strip()
    assert p["source_hash"]["ddfv"] == source_hash("ddfv")


def test_config_hash_ignores_key_order():
    assert config_hash({"a": 1, "b": [1, 2]}) == config_hash({"b": [1, 2], "a": 1})
    assert config_hash({"a": 1}) != config_hash({"a": 2})


def test_git_is_asked_once_per_process_and_path(monkeypatch, tmp_path):
    from mcfbench.storage import provenance as module

    calls, run = [], subprocess.run
    monkeypatch.setattr(module.subprocess, "run",
                        lambda args, **kw: calls.append(args[1]) or run(args, **kw))
    module.git_commit.cache_clear()
    first = module.git_commit()
    assert module.git_commit() == first and calls == ["rev-parse", "status"]
    assert module.git_commit(tmp_path) == ("unknown", None)     # another path: asked
    assert calls == ["rev-parse", "status", "rev-parse"]
    module.git_commit.cache_clear()
