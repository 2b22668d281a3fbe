"""The code identity of a set of modules: their import closure, hashed.

The closure of root modules is found by reading every module's source, never by
importing it (:mod:`ast`): a module's references are

* every ``import a.b`` and ``from a.b import c`` anywhere in the file, the
  function-level (lazy) imports included, relative imports resolved; ``from a
  import b`` where ``a.b`` is a module counts as that module;
* every string constant ``"a.b:Name"`` whose ``a.b`` is a module of the given
  packages (the registry names the schemes' flow classes so);
* every ``importlib.import_module("a.b")`` (or ``import_module``) whose name is a
  constant.

Importing ``a.b.c`` runs ``a/__init__.py`` and ``a/b/__init__.py``: a module's
packages' ``__init__`` files are in the closure with it. A name built at run time
(``import_module(f"...{name}")``) is not followed: what a listing loads by name is
the listing's business (:mod:`mcfbench.running.identity`).

Only the modules of ``packages`` (top-level names: the repository's, or any
outside package given) are followed and hashed, each by its path below its
package's folder and the SHA-256 of its bytes. An import of another top-level
name outside the standard library is not followed: the version of the
distribution that provides it (``importlib.metadata.packages_distributions``),
and of the distributions that one requires (not its extras), are the identity's
instead, so a numpy or scipy upgrade changes the identity of every closure that
imports it. A name no installed distribution provides is listed as unresolved.

Data files read by the code are in an identity by the SHA-256 of their bytes when
the caller names them (:func:`data_hashes`): no source analysis finds them.

``stop`` names modules that are not followed and not hashed when met as a
reference (a listing that names every scheme, say), unless they are roots.

Everything is cached per process (sources are read once; a closure once per
root): a change made to a file after its first reading is seen by the next
process. :func:`clear_caches` forgets it all (tests).
"""

import ast
import functools
import hashlib
import importlib.util
import re
import sys
from importlib import metadata
from pathlib import Path

from mcfbench.storage.provenance import distribution_headers, requirement_name

REPOSITORY_PACKAGES = ("ddfv", "baselines", "kept_factor", "mcfbench")
"""The repository's top-level packages: the ones whose modules are hashed."""

_QUALIFIED_NAME = re.compile(r"^([A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*):[A-Za-z_]\w*$")
"""``"package.module:Name"``."""

DIGITS = 16
"""Hex digits kept of each SHA-256 (64 bits: the digests name files, not secrets)."""


@functools.cache
def package_folder(top):
    """The folder holding the top-level package or module ``top`` (the
    ``sys.path`` entry it is found in; nothing is imported), or None."""
    spec = importlib.util.find_spec(top)
    if spec is None or spec.origin in (None, "built-in", "frozen"):
        return None
    origin = Path(spec.origin).resolve()
    return origin.parent.parent if origin.name == "__init__.py" else origin.parent


@functools.cache
def module_file(name, packages=REPOSITORY_PACKAGES):
    """The source file of module ``name`` if it is one of ``packages``' (a
    package's ``__init__.py``), else None."""
    top, *rest = name.split(".")
    if top not in packages:
        return None
    folder = package_folder(top)
    if folder is None:
        return None
    path = folder.joinpath(top, *rest)
    if (path / "__init__.py").is_file():
        return path / "__init__.py"
    if path.with_suffix(".py").is_file():
        return path.with_suffix(".py")
    return None


def _absolute(name, level, module, is_package):
    """The absolute name of ``from <level dots><name> import ...`` in ``module``."""
    if level == 0:
        return name
    parts = module.split(".") if is_package else module.split(".")[:-1]
    base = parts[:len(parts) - (level - 1)]
    return ".".join(base + ([name] if name else []))


@functools.cache
def references(name, packages=REPOSITORY_PACKAGES):
    """What module ``name`` (one of ``packages``') names: ``(modules, candidates)``,
    absolute module names it imports for sure (``import a.b``, ``from a.b import``,
    ``import_module("a.b")``, ``"a.b:Name"``) and names that are modules only if they
    resolve (``a.b.c`` of ``from a.b import c``)."""
    path = module_file(name, packages)
    is_package = path.name == "__init__.py"
    tree = ast.parse(path.read_bytes(), filename=str(path))
    modules, candidates = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = _absolute(node.module or "", node.level, name, is_package)
            modules.add(base)
            candidates.update(f"{base}.{alias.name}" for alias in node.names
                              if alias.name != "*")
        elif isinstance(node, ast.Constant) and isinstance(node.value, str):
            match = _QUALIFIED_NAME.match(node.value)
            if match and module_file(match.group(1), packages) is not None:
                modules.add(match.group(1))
        elif isinstance(node, ast.Call) and _is_import_module(node.func) and node.args \
                and isinstance(node.args[0], ast.Constant) \
                and isinstance(node.args[0].value, str):
            target = node.args[0].value
            dots = len(target) - len(target.lstrip("."))
            modules.add(_absolute(target[dots:], dots, name, is_package))
    return frozenset(modules), frozenset(candidates)


def _is_import_module(func):
    """``importlib.import_module`` or a bare ``import_module``."""
    return (isinstance(func, ast.Attribute) and func.attr == "import_module") or \
        (isinstance(func, ast.Name) and func.id == "import_module")


def _with_packages(name):
    """``name`` and the packages it lies in: ``a.b.c`` -> ``a``, ``a.b``, ``a.b.c``."""
    parts = name.split(".")
    return [".".join(parts[:k]) for k in range(1, len(parts) + 1)]


def closure(roots, packages=REPOSITORY_PACKAGES, stop=frozenset()):
    """The import closure of the modules ``roots`` (a tuple of module names).

    Parameters
    ----------
    roots : tuple of str
        Modules of ``packages``.
    packages : tuple of str
        Top-level names whose modules are followed and hashed.
    stop : frozenset of str
        Modules neither followed nor hashed when met as a reference (a root
        is always followed).

    Returns
    -------
    modules : frozenset of str
        The modules of ``packages`` in the closure, the packages' ``__init__``
        included.
    outside : frozenset of str
        The top-level names of the other modules it imports, the standard
        library's left out.

    Raises
    ------
    ValueError
        A root that is not a module of ``packages``.
    """
    parts = [_root_closure(root, packages, stop) for root in roots]
    return (frozenset().union(*(m for m, _ in parts)),
            frozenset().union(*(o for _, o in parts)))


@functools.cache
def _root_closure(root, packages, stop):
    """:func:`closure` of one root (the closure of several is their union)."""
    if module_file(root, packages) is None:
        raise ValueError(f"{root!r} is not a module of the packages {', '.join(packages)}")
    modules, outside, todo = set(), set(), [root]
    while todo:
        name = todo.pop()
        for part in _with_packages(name):
            if part in modules or (part in stop and part != root):
                continue
            if module_file(part, packages) is None:
                top = part.split(".")[0]
                if top not in packages and top not in sys.stdlib_module_names:
                    outside.add(top)
                break
            modules.add(part)
            found, candidates = references(part, packages)
            todo += found
            todo += [c for c in candidates if module_file(c, packages) is not None]
    return frozenset(modules), frozenset(outside)


@functools.cache
def module_path(name, packages=REPOSITORY_PACKAGES):
    """The path of module ``name``'s file below its package's folder
    (``baselines/bgn.py``): the same in every copy of the repository."""
    path = module_file(name, packages)
    return path.relative_to(package_folder(name.split(".")[0])).as_posix()


@functools.cache
def file_hash(path):
    """SHA-256 (:data:`DIGITS` hex digits) of the bytes of the file ``path``."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:DIGITS]


def module_hashes(modules, packages=REPOSITORY_PACKAGES):
    """``{path below its package's folder: SHA-256 of its bytes}`` of ``modules``."""
    return {module_path(m, packages): file_hash(module_file(m, packages))
            for m in sorted(modules)}


def data_hashes(paths):
    """``{path: SHA-256 of its bytes}`` of data files, each path below the folder
    of the repository's packages when it lies there (``mcfbench/data/...``).

    Raises
    ------
    FileNotFoundError
        A path that is not a file, named.
    """
    base = package_folder("mcfbench")
    hashes = {}
    for path in paths:
        path = Path(path).resolve()
        if not path.is_file():
            raise FileNotFoundError(f"data file {path} of a code identity is missing")
        key = path.relative_to(base).as_posix() if base in path.parents else str(path)
        hashes[key] = file_hash(path)
    return dict(sorted(hashes.items()))


@functools.cache
def _providers():
    """``{top-level import name: [distributions]}`` of the installed distributions
    (read once: scanning every distribution's file list costs about 0.1 s)."""
    return metadata.packages_distributions()


@functools.cache
def distribution_version(name):
    """The installed version of distribution ``name`` (a normalised name: lower
    case, ``-`` for ``_``; None if not installed)."""
    try:
        return metadata.version(name)
    except metadata.PackageNotFoundError:
        return None


@functools.cache
def _requirements(name):
    """The distributions ``name`` requires (its extras' left out)."""
    try:
        headers = distribution_headers(metadata.distribution(name))
    except metadata.PackageNotFoundError:
        return ()
    return tuple(requirement_name(r) for r in headers.get_all("Requires-Dist") or []
                 if "extra" not in r.partition(";")[2])


def _key(distribution):
    return distribution.lower().replace("_", "-")


@functools.cache
def distribution_versions(tops):
    """``({distribution: version}, [unresolved])`` of the top-level import names
    ``tops`` (a frozenset): the distributions providing them and, recursively, those they
    require (installed ones), by their normalised names; the names no installed
    distribution provides, sorted."""
    providers = _providers()
    versions, unresolved = {}, []
    todo = []
    for top in sorted(tops):
        if top in providers:
            todo += providers[top]
        else:
            unresolved.append(top)
    while todo:
        name = _key(todo.pop())
        if name in versions:
            continue
        version = distribution_version(name)
        if version is None:
            continue
        versions[name] = version
        todo += _requirements(name)
    return dict(sorted(versions.items())), unresolved


def code_identity(roots, packages=REPOSITORY_PACKAGES, stop=frozenset(), data=()):
    """The code identity of the modules ``roots``: a JSON-serialisable dict.

    Parameters
    ----------
    roots : iterable of str
        Module names of ``packages``.
    packages, stop
        As :func:`closure`'s.
    data : iterable of path
        Data files the code reads (:func:`data_hashes`).

    Returns
    -------
    dict
        ``modules`` (path -> SHA-256, :func:`module_hashes`), ``distributions``
        (distribution -> version, :func:`distribution_versions`, of the outside
        names imported and of the packages given outside the repository's),
        ``unresolved``
        (imported names no installed distribution provides), ``data`` (path ->
        SHA-256), ``python`` (its version).
    """
    modules, outside = closure(tuple(sorted(set(roots))), tuple(packages), frozenset(stop))
    # an outside package given is hashed, and its distribution's version counts too
    given = {m.split(".")[0] for m in modules} - set(REPOSITORY_PACKAGES)
    versions, unresolved = distribution_versions(outside | given)
    return {"modules": module_hashes(modules, tuple(packages)), "distributions": dict(versions),
            "unresolved": list(unresolved), "data": data_hashes(data),
            "python": ".".join(map(str, sys.version_info[:3]))}


_CACHES = (package_folder, module_file, references, _root_closure, module_path, file_hash,
           _providers, distribution_version, _requirements, distribution_versions)


def clear_caches():
    """Forget every file, closure and version read (a test that edits files)."""
    for cached in _CACHES:
        cached.cache_clear()
