"""A run's code identity: the code that computes the run, and nothing else.

:func:`run_identity` is what the run store keys a record's code by. It is the
import closure (:mod:`mcfbench.storage.code_identity`: static, lazy imports,
``"module:Class"`` strings and constant ``import_module`` names followed) of

* the scheme: its flow class's module (the registry entry's ``"module:Class"``;
  an outside package's flow is followed and hashed as the repository's are, and
  its ``source``: distribution, version, files' SHA-256), for ``NAME@INTEGRATOR``
  the integrator's module, for ``NAME+STRATEGY`` (``+remesh``, ``+surgery``) its
  hook's module (:func:`scheme_roots`: the remeshing's, the neck's cut's, in no
  other run's), and the entry's values that change the numbers (its
  flow, options and integrator: :func:`scheme_values`; not its label or style);
* the problem: the module that defines it (``Problem.module`` where the problem
  has one, else the module of its ``params`` function) and the registry module
  that defines :class:`~mcfbench.running.problems.Problem` and the metrics, with
  the data files it reads (``Problem.data_files``: a committed real mesh's mesh
  file and its reference ``.json`` and ``.npz``);
* the harness that steps, checks and measures a run: the closure of
  :mod:`mcfbench.running.run` (driver, solver, integrators, invariants,
  monitors, metrics, records, frames and the surface generators);

plus the versions of the installed distributions those modules import (and of
what those require) and the Python version.

**The stop rule.** The listings are not computing code: the scheme registry
(:mod:`mcfbench.running.schemes`: every scheme's ``"module:Class"``), the problem
registry (:mod:`mcfbench.running.problems`: every problem) and the discovery
folders (:mod:`mcfbench.problems`, :mod:`mcfbench.schemes`) are neither followed nor hashed where
another module imports them (:data:`STOP`), so the harness's ``run`` does not
reach every scheme through the registry, and a new entry in a listing changes no
other run's identity. What a scheme's entry sets that changes the numbers (its
flow, options and integrator) is part of the identity as values; a problem's
defining module (its parameters, time rule, metrics) is a root.

Everything is cached per process: the identities of every run of the full matrix
cost a fraction of a second.
"""

import functools
import importlib
import json

from mcfbench.storage import code_identity as code
from mcfbench.storage.provenance import config_hash

HARNESS = ("mcfbench.running.run",)
"""The roots of the harness code every run shares."""

STOP = frozenset({"mcfbench.running.schemes", "mcfbench.running.problems", "mcfbench.problems",
                  "mcfbench.running.remeshing", "mcfbench.running.surgery",
                  "mcfbench.schemes"})
"""The listings: not followed where they are imported (module docstring); and the mesh
strategies' hooks (:mod:`mcfbench.running.remeshing`, :mod:`mcfbench.running.surgery`),
which the harness's ``run`` imports for every run but only a ``NAME+STRATEGY``
scheme's runs use: a root of those (:func:`scheme_roots`)."""

PROBLEM_DEFINITIONS = ("mcfbench.running.problem", "mcfbench.running.observers")
"""The modules defining ``Problem`` and the metric observers: roots of every problem."""


def _module_of(qualified):
    """``"a.b"`` of ``"a.b:Name"``."""
    return qualified.partition(":")[0]


def scheme_roots(scheme):
    """The modules of ``scheme`` (a registry name, ``NAME@INTEGRATOR`` and
    ``NAME+STRATEGY`` included): its flow's, for another integrator than Euler the
    integrator's, and for a mesh strategy its hook's class's
    (:data:`mcfbench.running.remeshing.STRATEGIES`; a composed hook's ``modules``: its
    parts')."""
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.remeshing import STRATEGIES
    from mcfbench.running.schemes import get_scheme

    entry = get_scheme(scheme)
    roots = [_module_of(entry.flow)]
    if entry.integrator != "euler":
        roots.append(INTEGRATORS[entry.integrator].__module__)
    if entry.mesh_strategy != "none":
        hook = STRATEGIES[entry.mesh_strategy]
        roots.extend(getattr(hook, "modules", (hook.__module__,)))
    return tuple(roots)


def scheme_values(scheme):
    """What the registry entry of ``scheme`` sets that changes a run's numbers: its
    flow, options, integrator and mesh strategy (when not ``"none"``), and an installed
    package's ``source``
    (distribution, version, SHA-256 of its files); not its label, style or
    description."""
    from mcfbench.running.schemes import get_scheme

    entry = get_scheme(scheme)
    values = {"flow": entry.flow, "options": entry.options, "integrator": entry.integrator}
    if entry.mesh_strategy != "none":   # (the others' identities as before the strategies)
        values["mesh_strategy"] = entry.mesh_strategy
    source = getattr(entry, "source", None)
    return {**values, "source": source} if source else values


def problem_roots(problem):
    """The modules defining ``problem`` (a :class:`~mcfbench.running.problems.Problem`):
    its ``module`` (a name or a module) where it has one, else its ``params``
    function's, and :data:`PROBLEM_DEFINITIONS`."""
    module = getattr(problem, "module", None)
    if module is None:
        module = getattr(problem.params, "__module__", None)
    module = getattr(module, "__name__", module)
    roots = set(PROBLEM_DEFINITIONS)
    if module is not None:
        roots.add(module)
    return tuple(sorted(roots))


def problem_data(problem):
    """The data files ``problem`` reads (``Problem.data_files``: a committed real
    mesh's mesh file and reference answers; none for a generated surface)."""
    return tuple(getattr(problem, "data_files", ()))


def _packages(roots):
    """The repository's packages and the outside ones ``roots`` lie in."""
    outside = sorted({r.split(".")[0] for r in roots} - set(code.REPOSITORY_PACKAGES))
    return (*code.REPOSITORY_PACKAGES, *outside)


@functools.cache
def _identity(roots, data):
    return code.code_identity(roots, _packages(roots), STOP, data)


@functools.cache
def _digest(scheme, problem):
    from mcfbench.running.problems import PROBLEMS

    definition = PROBLEMS.get(problem)
    if definition is None:      # a user's mesh file: its bytes are the spec's (SHA-256)
        problem_part, data = PROBLEM_DEFINITIONS, ()
    else:
        problem_part, data = problem_roots(definition), problem_data(definition)
    roots = tuple(sorted({*HARNESS, *scheme_roots(scheme), *problem_part}))
    identity = {**_identity(roots, data), "scheme": scheme_values(scheme)}
    return json.dumps(identity, sort_keys=True, default=str)


def run_identity(scheme, problem):
    """The code identity of a run of ``scheme`` (a registry name, ``NAME@INTEGRATOR``
    included) on ``problem`` (a registry name, or another name for a user's mesh file,
    e.g. the gallery's ``"gallery"``: the problem definitions' modules only, the file
    being in the run's spec by its SHA-256): a JSON-serialisable dict, its
    ``modules`` (path -> SHA-256), ``distributions`` (name -> version),
    ``unresolved``, ``data`` (path -> SHA-256) and ``python``
    (:func:`mcfbench.storage.code_identity.code_identity`) and ``scheme``
    (:func:`scheme_values`); a fresh copy per call."""
    return json.loads(_digest(scheme, problem))


def identity_digest(identity):
    """Short SHA-256 (16 hex digits) of a :func:`run_identity`."""
    return config_hash(identity)


def registry_identity():
    """The code identity of every run the registries can make, as one digest: the
    closure of the harness, every scheme's and every problem's roots (the union of
    their :func:`run_identity`), with every problem's data files. The code a
    pipeline's kernels' compilation and its studies' runs depend on until each run
    is keyed by its own."""
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.problems import PROBLEMS
    from mcfbench.running.schemes import SCHEMES

    roots = {*HARNESS, *(c.__module__ for c in INTEGRATORS.values())}
    data = set()
    for scheme in SCHEMES:
        roots.update(scheme_roots(scheme))
    for problem in PROBLEMS.values():
        roots.update(problem_roots(problem))
        data.update(problem_data(problem))
    roots = tuple(sorted(roots))
    values = {name: scheme_values(name) for name in SCHEMES}
    return identity_digest({**_identity(roots, tuple(sorted(data))), "schemes": values})


def forget_identities():
    """Forget every identity, file and version read (a test that changes them)."""
    _identity.cache_clear()
    _digest.cache_clear()
    code.clear_caches()
