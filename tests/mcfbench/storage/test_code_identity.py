"""The import closure and its hash (mcfbench/storage/code_identity.py), on small
synthetic packages put on ``sys.path``."""

import textwrap

import pytest

from mcfbench.storage import code_identity as ci

SOURCES = {
    "__init__.py": "",
    "root.py": """
        import json
        from pkgx import sub
        from .rel import value

        FLOW = "pkgx.flows.impl:Impl"
        NOT_A_MODULE = "pkgx.nowhere:Thing"
        LABEL = "time: 12:30"


        def lazy():
            from pkgx.lazy import g
            return g


        def by_name():
            import importlib
            return importlib.import_module("pkgx.dynamic")


        def computed(name):
            import importlib
            return importlib.import_module(f"pkgx.{name}")


        def listing():
            from pkgx import listing
            return listing
        """,
    "sub.py": "import numpy\n",
    "rel.py": "value = 1\n",
    "lazy.py": "def g():\n    from . import deep\n    return deep\n",
    "deep.py": "",
    "dynamic.py": "import no_such_distribution_anywhere\n",
    "flows/__init__.py": "",
    "flows/impl.py": "class Impl:\n    pass\n",
    "listing.py": "from pkgx import everything\n",
    "everything.py": "",
    "unused.py": "",
}


@pytest.fixture
def pkgx(tmp_path, monkeypatch):
    """The package ``pkgx`` of :data:`SOURCES` in ``tmp_path``, first on sys.path."""
    for name, text in SOURCES.items():
        path = tmp_path / "pkgx" / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(textwrap.dedent(text))
    monkeypatch.syspath_prepend(str(tmp_path))
    ci.clear_caches()
    yield tmp_path / "pkgx"
    ci.clear_caches()


def _paths(modules):
    return {m.replace(".", "/") for m in modules}


def test_the_closure_follows_lazy_imports_qualified_names_and_constant_import_module(pkgx):
    """Function-level imports, relative ones, ``from a import module``, ``"a.b:Name"``
    and ``import_module("a.b")`` are followed, with the packages' ``__init__``; a name
    built at run time, a string naming no module and an unimported module are not;
    outside names are listed by their top-level name, the standard library's left out."""
    modules, outside = ci.closure(("pkgx.root",), ("pkgx",))
    assert modules == {"pkgx", "pkgx.root", "pkgx.sub", "pkgx.rel", "pkgx.lazy", "pkgx.deep",
                       "pkgx.dynamic", "pkgx.flows", "pkgx.flows.impl", "pkgx.listing",
                       "pkgx.everything"}
    assert outside == {"numpy", "no_such_distribution_anywhere"}


def test_a_stop_module_is_neither_followed_nor_hashed_unless_a_root(pkgx):
    stop = frozenset({"pkgx.listing"})
    modules, _ = ci.closure(("pkgx.root",), ("pkgx",), stop)
    assert "pkgx.listing" not in modules and "pkgx.everything" not in modules
    modules, _ = ci.closure(("pkgx.root", "pkgx.listing"), ("pkgx",), stop)
    assert {"pkgx.listing", "pkgx.everything"} <= modules


def test_a_root_outside_the_packages_is_named(pkgx):
    with pytest.raises(ValueError, match="'pkgx.nowhere' is not a module"):
        ci.closure(("pkgx.nowhere",), ("pkgx",))


def test_the_identity_hashes_each_module_by_path_and_bytes(pkgx):
    """Editing one module changes its own hash only; the paths are below the
    package's folder; an edit of a module outside the closure changes nothing."""
    before = ci.code_identity(["pkgx.root"], ("pkgx",))
    assert set(before["modules"]) == {"pkgx/__init__.py", "pkgx/root.py", "pkgx/sub.py",
                                      "pkgx/rel.py", "pkgx/lazy.py", "pkgx/deep.py",
                                      "pkgx/dynamic.py", "pkgx/flows/__init__.py",
                                      "pkgx/flows/impl.py", "pkgx/listing.py",
                                      "pkgx/everything.py"}
    (pkgx / "unused.py").write_text("x = 2\n")
    (pkgx / "deep.py").write_text("y = 3\n")
    ci.clear_caches()
    after = ci.code_identity(["pkgx.root"], ("pkgx",))
    changed = {p for p in before["modules"] if before["modules"][p] != after["modules"][p]}
    assert changed == {"pkgx/deep.py"}


def test_third_party_imports_count_by_their_distributions_versions(pkgx, monkeypatch):
    """numpy's version (installed) is in the identity, a name no distribution
    provides is unresolved, and a new numpy version changes the identity."""
    import numpy

    identity = ci.code_identity(["pkgx.root"], ("pkgx",))
    assert identity["distributions"]["numpy"] == numpy.__version__
    # pkgx, a package given, is hashed and would count by its version: not installed
    assert identity["unresolved"] == ["no_such_distribution_anywhere", "pkgx"]
    real = ci.distribution_version
    with monkeypatch.context() as patch:
        patch.setattr(ci, "distribution_version",
                      lambda name: "999.0" if name == "numpy" else real(name))
        ci.clear_caches()
        bumped = ci.code_identity(["pkgx.root"], ("pkgx",))
    assert bumped["distributions"]["numpy"] == "999.0"
    assert bumped["modules"] == identity["modules"]
    # a closure without numpy: no version of it
    assert "numpy" not in ci.code_identity(["pkgx.rel"], ("pkgx",))["distributions"]


def test_a_distribution_s_requirements_count_too():
    """scipy requires numpy: a closure importing scipy alone carries numpy's version."""
    versions, unresolved = ci.distribution_versions(frozenset({"scipy"}))
    assert set(versions) == {"scipy", "numpy"} and unresolved == []


def test_data_files_by_their_bytes(tmp_path, pkgx):
    data = tmp_path / "mesh.obj"
    data.write_text("v 0 0 0\n")
    first = ci.code_identity(["pkgx.rel"], ("pkgx",), data=[data])["data"]
    assert first == {str(data.resolve()): ci.file_hash(data)}
    data.write_text("v 0 0 1\n")
    ci.clear_caches()
    assert ci.code_identity(["pkgx.rel"], ("pkgx",), data=[data])["data"] != first
    with pytest.raises(FileNotFoundError, match="missing.obj"):
        ci.data_hashes([tmp_path / "missing.obj"])


def test_an_installed_outside_package_given_counts_by_its_files_and_version():
    """A package outside the repository (here tqdm) given to follow: its modules are
    hashed and its distribution's version is in the identity."""
    from importlib import metadata

    identity = ci.code_identity(["tqdm.std"], ("tqdm",))
    assert {"tqdm/__init__.py", "tqdm/std.py"} <= set(identity["modules"])
    assert identity["distributions"]["tqdm"] == metadata.version("tqdm")
