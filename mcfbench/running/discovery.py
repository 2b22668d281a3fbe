"""How the registries find schemes and problems: a folder scan and entry points.

Both registries (:mod:`mcfbench.running.schemes`, :mod:`mcfbench.running.problems`)
are built here in one deterministic order:

1. the built-ins, the modules of a folder of the package (``mcfbench/schemes/``,
   ``mcfbench/problems/``), sorted by their ``ORDER`` (an integer; a module without
   one comes after those with one), then by module name; each module declares one
   item (``SCHEME``, ``PROBLEM``) or a list (``SCHEMES``, ``PROBLEMS``), in its
   own order;
2. installed packages' entry points of the group (``mcfbench.schemes``,
   ``mcfbench.problems``), sorted by the entry point's name; each loads one item or
   a list of them.

Every item gets the module that declared it (``module``), and an entry point's its
package's ``source``: distribution, version and the SHA-256 of its files
(:func:`package_source`), so that editing an editable install's files changes its
runs' code identity. Two sources declaring one name are an error naming both.
"""

import hashlib
import importlib
import pkgutil
import sys
from dataclasses import replace
from pathlib import Path

LAST = sys.maxsize
"""The ``ORDER`` of a built-in module that declares none: after the others."""


class RegistryError(ValueError):
    """A module or entry point that declares nothing valid, or a name declared twice."""


def module_items(module, single, many, cls):
    """The items of type ``cls`` a module declares: its attribute ``single`` (one) or
    ``many`` (a list).

    Raises
    ------
    RegistryError
        Neither, or an item that is not a ``cls``.
    """
    if hasattr(module, many):
        items = list(getattr(module, many))
    elif hasattr(module, single):
        items = [getattr(module, single)]
    else:
        raise RegistryError(f"{module.__name__}: a {cls.__name__.lower()} module defines "
                            f"{single} (a {cls.__name__}) or {many} (a list of them)")
    bad = [repr(item)[:60] for item in items if not isinstance(item, cls)]
    if bad:
        raise RegistryError(f"{module.__name__}: {single}/{many} holds something that is not "
                            f"a {cls.__name__}: {', '.join(bad)}")
    return items


def folder_modules(paths, package):
    """Import every module of ``paths`` (a package's ``__path__``) as
    ``package.<name>``, in the built-ins' order: ``ORDER``, then the name.

    Returns
    -------
    list of module
    """
    modules = [importlib.import_module(f"{package}.{info.name}")
               for info in pkgutil.iter_modules(paths)]
    return sorted(modules, key=lambda m: (getattr(m, "ORDER", LAST), m.__name__))


def package_source(module_name, distribution):
    """``{"distribution", "version", "files_sha256"}`` of an installed package's
    module: the SHA-256 over the sorted relative paths and bytes of every file of the
    module's top-level package (its one file for a module outside a package), read
    where the import system finds them (an editable install's source tree).

    Parameters
    ----------
    module_name : str
        The entry point's module.
    distribution : importlib.metadata.Distribution or None
    """
    top = importlib.import_module(module_name.partition(".")[0])
    origin = Path(top.__file__).resolve()
    root = origin.parent if origin.name == "__init__.py" else origin
    files = sorted(p for p in (root.rglob("*") if root.is_dir() else [root])
                   if p.is_file() and "__pycache__" not in p.parts)
    digest = hashlib.sha256()
    for path in files:
        digest.update(str(path.relative_to(root.parent)).encode() + b"\0")
        digest.update(hashlib.sha256(path.read_bytes()).digest())
    return {"distribution": None if distribution is None else distribution.metadata["Name"],
            "version": None if distribution is None else distribution.version,
            "files_sha256": digest.hexdigest()}


def entry_point_items(group, cls):
    """``(items, where, module, source)`` of every entry point of ``group``, sorted by
    name: what it loads (one ``cls`` or a list), a phrase naming it, its module's name
    and its :func:`package_source`.

    Raises
    ------
    RegistryError
        An entry point that fails to load or loads something else than ``cls``
        items, naming it and its distribution.
    """
    from importlib.metadata import entry_points

    found = []
    for point in sorted(entry_points(group=group), key=lambda e: (e.name, e.value)):
        dist = getattr(point, "dist", None)
        where = (f"entry point {point.name!r} = {point.value!r} of "
                 f"{dist.metadata['Name'] + ' ' + dist.version if dist else 'no distribution'}")
        try:
            loaded = point.load()
        except Exception as error:
            raise RegistryError(f"{group}: {where} does not load: "
                                f"{type(error).__name__}: {error}") from error
        items = list(loaded) if isinstance(loaded, (list, tuple)) else [loaded]
        if not items or not all(isinstance(item, cls) for item in items):
            raise RegistryError(f"{group}: {where} loads {loaded!r:.80}, not a "
                                f"{cls.__name__} or a list of them")
        found.append((items, where, point.module, package_source(point.module, dist)))
    return found


def _origin(item):
    """Who declared a registered item: its module, and its distribution if installed."""
    where = item.module or "the registry"
    source = item.source or {}
    return f"{where} ({source['distribution']} {source['version']})" if source else where


def build_registry(declared, what, registry=None):
    """Register ``(items, where, module, source)`` in order into ``registry`` (default
    a new dict; name -> item); each item gets its ``module`` and ``source``.

    Raises
    ------
    RegistryError
        A name declared twice (or already in ``registry``), naming both sources.
    """
    registry = {} if registry is None else registry
    origin = {name: _origin(item) for name, item in registry.items()}
    for items, where, module, source in declared:
        for item in items:
            if item.name in origin:
                raise RegistryError(f"{what} {item.name!r} is declared twice: by "
                                    f"{origin[item.name]} and by {where}; rename one")
            registry[item.name] = replace(item, module=module, source=source)
            origin[item.name] = where
    return registry


def discover(paths, package, single, many, cls, group=None, registry=None):
    """Find a kind's items: the modules of a folder, then the entry points of
    ``group`` (the module docstring's order), into ``registry``.

    Parameters
    ----------
    paths : list of str
        The folder (a package's ``__path__``: ``mcfbench.schemes``, ``mcfbench.problems``).
    package : str
        Its package's name.
    single, many : str
        The attribute names a module declares its items by.
    cls : type
        :class:`~mcfbench.running.scheme.Scheme` or :class:`~mcfbench.running.problem.Problem`.
    group : str, optional
        The entry-point group (None: the folder only).
    registry : dict, optional
        Name -> item, added to in place (default a new dict).

    Returns
    -------
    registry : dict
        Name -> item.
    modules : dict
        Name of every item found -> the module object that declared it (a problem
        module's ``surface`` and ``METRICS`` are registered from it).
    """
    declared, modules = [], {}
    for module in folder_modules(paths, package):
        items = module_items(module, single, many, cls)
        declared.append((items, f"{module.__name__} ({module.__file__})", module.__name__,
                         None))
        modules.update((item.name, module) for item in items)
    for items, where, module_name, source in (entry_point_items(group, cls) if group else ()):
        declared.append((items, where, module_name, source))
        modules.update((item.name, sys.modules[module_name]) for item in items)
    return build_registry(declared, cls.__name__.lower(), registry), modules
