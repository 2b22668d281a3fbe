"""The registry of schemes: name -> :class:`~mcfbench.running.scheme.Scheme`.

The command line, the studies, the pipeline, the tables, the figures and the
report all look schemes up here. The registry is found, not listed
(:mod:`mcfbench.running.discovery`): the built-in schemes are the modules of
:mod:`mcfbench.schemes` (a module declares ``SCHEME`` or ``SCHEMES``; their order
is the modules' ``ORDER``: DDFV and its variants, the cotangent family, cMCF, BGN,
MDR, DeTurck, KLL), then every installed package's entry points of the group
``mcfbench.schemes``, sorted by name. A new scheme is one module (a class following
:class:`mcfbench.running.flow.SchemeFlow`, named as ``"module:Class"`` and imported
on first use) and one file of :mod:`mcfbench.schemes`, or an entry point of one's
own package (``docs/extending.md``). A name declared twice is an error naming both.

Every scheme is stepped by the paper's semi-implicit Euler step unless
asked otherwise; ``<name>@<integrator>`` (e.g. ``cotan@bdf2``) names the
scheme ``<name>`` stepped by another integrator of
:data:`mcfbench.running.integrators.INTEGRATORS` (:func:`get_scheme`), so
that a study lists it like any scheme (the matrix, the beyond study);
``<name>+<strategy>`` (``cotan+remesh``, ``cotan@bdf2+remesh``, ``cotan+surgery``:
the integrator first) the scheme whose runs also treat the mesh by a strategy of
:data:`~mcfbench.running.scheme.MESH_STRATEGIES` (:func:`~mcfbench.running.scheme.parse_name`;
``+surgery`` goes on through a neck pinch, :mod:`mcfbench.running.surgery`).
"""

from dataclasses import replace

import mcfbench.schemes
from mcfbench.running.discovery import discover
from mcfbench.running.integrators import INTEGRATORS
from mcfbench.running.scheme import (  # noqa: F401 (the API)
    MATRICES, MESH_STRATEGIES, TANGENTIAL, Scheme, parse_name)

GROUP = "mcfbench.schemes"
"""The entry-point group of installed packages' schemes."""

SCHEMES, _ = discover(mcfbench.schemes.__path__, mcfbench.schemes.__name__, "SCHEME", "SCHEMES",
                      Scheme, GROUP)
"""Scheme name -> :class:`Scheme`, in the registry's order (module docstring)."""


def split_name(name):
    """``(name without the integrator, integrator)`` of a scheme name: ``"cotan@bdf2"`` ->
    ``("cotan", "bdf2")``, ``"cotan"`` -> ``("cotan", "euler")``, ``"cotan@bdf2+remesh"``
    -> ``("cotan+remesh", "bdf2")`` (a mesh strategy stays with its scheme:
    :func:`~mcfbench.running.scheme.parse_name` gives the registry entry's name)."""
    base, integrator, strategy = parse_name(name)
    return joined_name(base, "euler", strategy), integrator


def joined_name(base, integrator, strategy=None):
    """The scheme name of ``base`` stepped by ``integrator`` (:func:`split_name`'s
    inverse): ``base`` itself for Euler, else ``base@integrator``; a mesh
    ``strategy`` (default ``base``'s own ``+STRATEGY``, if any) after it."""
    name, _, own = base.partition("+")
    strategy = (own or "none") if strategy is None else strategy
    stepped = name if integrator == "euler" else f"{name}@{integrator}"
    return stepped if strategy == "none" else f"{stepped}+{strategy}"


def get_scheme(name, registry=None):
    """The registry entry ``name``, or ``<name>@<integrator>``: that entry stepped by
    another integrator (its label says which; hollow markers), or with ``+<strategy>``:
    its runs treat the mesh by that strategy too (its label says which; dashed
    lines): ``+remesh`` remeshes, ``+surgery`` goes on through a neck pinch.

    Parameters
    ----------
    name : str
    registry : dict, optional
        Name -> :class:`Scheme` (default :data:`SCHEMES`).

    Raises
    ------
    ValueError
        Unknown name, integrator or strategy, listing the known ones.
    """
    registry = SCHEMES if registry is None else registry
    base, integrator, strategy = parse_name(name)
    if base not in registry:
        raise ValueError(f"unknown scheme {name!r}; choose one of "
                         f"{', '.join(registry)} (or NAME@INTEGRATOR, NAME+STRATEGY, "
                         "NAME@INTEGRATOR+STRATEGY)")
    entry = registry[base]
    if name == base:
        return entry
    if integrator not in INTEGRATORS or "@" in name and integrator == "euler":
        raise ValueError(f"unknown integrator {integrator!r} in scheme {name!r}; choose one "
                         f"of {', '.join(i for i in INTEGRATORS if i != 'euler')}")
    if integrator != "euler" and entry.integrates_itself:
        raise ValueError(f"scheme {base!r} integrates in time itself: no {name!r}")
    if integrator != "euler":
        entry = replace(entry, name=joined_name(base, integrator, "none"), integrator=integrator,
                        label=f"{entry.label}, {INTEGRATORS[integrator].label}",
                        style={**entry.style, "markerfacecolor": "none"})
    if strategy != "none":
        entry = replace(entry, name=name, mesh_strategy=strategy,
                        label=f"{entry.label}, {strategy}",
                        style={**entry.style, "linestyle": "--"})
    return entry


def find_scheme(name, registry=None):
    """:func:`get_scheme`, or None for a name it does not know."""
    try:
        return get_scheme(name, registry)
    except ValueError:
        return None


def scheme_label(name):
    """The label of ``name`` in tables and legends (the name itself when unknown)."""
    entry = find_scheme(name)
    return name if entry is None else entry.label
