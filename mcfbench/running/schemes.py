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
``<name>+surgery`` names it with the surgery at a neck pinch
(:data:`mcfbench.running.scheme.CONTINUATIONS`, :mod:`mcfbench.running.continuation`).
"""

from dataclasses import replace

import mcfbench.schemes
from mcfbench.running.discovery import discover
from mcfbench.running.integrators import INTEGRATORS
from mcfbench.running.scheme import (CONTINUATIONS, MATRICES, TANGENTIAL,  # noqa: F401
                                     Scheme)

GROUP = "mcfbench.schemes"
"""The entry-point group of installed packages' schemes."""

SCHEMES, _ = discover(mcfbench.schemes.__path__, mcfbench.schemes.__name__, "SCHEME", "SCHEMES",
                      Scheme, GROUP)
"""Scheme name -> :class:`Scheme`, in the registry's order (module docstring)."""


def split_continuation(name):
    """``(name without its continuation, continuation)``: ``"cotan+surgery"`` ->
    ``("cotan", "surgery")``, ``"cotan@bdf2+surgery"`` -> ``("cotan@bdf2", "surgery")``,
    ``"cotan"`` -> ``("cotan", "none")`` (:data:`CONTINUATIONS`)."""
    rest, plus, continuation = name.rpartition("+")
    return (rest, continuation) if plus and continuation in CONTINUATIONS \
        and continuation != "none" else (name, "none")


def split_name(name):
    """``(registry name, integrator)`` of a scheme name: ``"cotan@bdf2"`` ->
    ``("cotan", "bdf2")``, ``"cotan"`` -> ``("cotan", "euler")``."""
    base, _, integrator = name.partition("@")
    return base, integrator or "euler"


def joined_name(base, integrator):
    """The scheme name of ``base`` stepped by ``integrator`` (:func:`split_name`'s
    inverse): ``base`` itself for Euler, else ``base@integrator``."""
    return base if integrator == "euler" else f"{base}@{integrator}"


def get_scheme(name, registry=None):
    """The registry entry ``name``, or ``<name>@<integrator>``: that entry stepped by
    another integrator (its label says which; hollow markers), or either with
    ``+surgery``: its runs go on through a neck pinch (:attr:`Scheme.continuation`).

    Parameters
    ----------
    name : str
    registry : dict, optional
        Name -> :class:`Scheme` (default :data:`SCHEMES`).

    Raises
    ------
    ValueError
        Unknown name or integrator, listing the known ones.
    """
    registry = SCHEMES if registry is None else registry
    rest, continuation = split_continuation(name)
    if continuation != "none":
        entry = get_scheme(rest, registry)
        return replace(entry, name=name, continuation=continuation,
                       label=f"{entry.label}, {continuation}")
    base, integrator = split_name(name)
    if base not in registry:
        raise ValueError(f"unknown scheme {name!r}; choose one of "
                         f"{', '.join(registry)} (or NAME@INTEGRATOR, NAME+surgery)")
    entry = registry[base]
    if name == base:
        return entry
    if integrator not in INTEGRATORS:
        raise ValueError(f"unknown integrator {integrator!r} in scheme {name!r}; choose one "
                         f"of {', '.join(INTEGRATORS)}")
    return replace(entry, name=name, integrator=integrator,
                   label=f"{entry.label}, {INTEGRATORS[integrator].label}",
                   style={**entry.style, "markerfacecolor": "none"})


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
