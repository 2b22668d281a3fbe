"""A run's code identity: the code that computes the run, and nothing else.

:func:`run_identity` is what the run store keys a record's code by. It is the
import closure (:mod:`mcfbench.storage.code_identity`: static, lazy imports,
``"module:Class"`` strings and constant ``import_module`` names followed) of

* the scheme: its flow class's module (the registry entry's ``"module:Class"``;
  an outside package's flow is followed and hashed as the repository's are),
  and for ``NAME@INTEGRATOR`` the integrator's module;
* the problem: the module that defines it (``Problem.module`` where the problem
  has one, else the module of its ``params`` function) and the registry module
  that defines :class:`~mcfbench.running.problems.Problem` and the metrics, with
  the data files it reads (``Problem.data_files`` where it has them; a committed
  real mesh's mesh file and its reference ``.json`` and ``.npz``);
* the harness that steps, checks and measures a run: the closure of
  :mod:`mcfbench.running.run` (driver, solver, integrators, invariants,
  monitors, metrics, records, frames and the surface generators);

plus the versions of the installed distributions those modules import (and of
what those require) and the Python version.

**The stop rule.** The listings are not computing code: the scheme registry
(:mod:`mcfbench.running.schemes`: every scheme's ``"module:Class"``), the problem
registry (:mod:`mcfbench.running.problems`: every problem) and the problems'
discovery folder (:mod:`mcfbench.problems`) are neither followed nor hashed where
another module imports them (:data:`STOP`), so the harness's ``run`` does not
reach every scheme through the registry, and a new entry in a listing changes no
other run's identity. What a registry entry sets that changes the numbers (a
scheme's options and integrator, a problem's parameters) belongs to the run's
spec, not to its code identity. A problem's defining module is a root, so the
problem registry is followed from there (today it defines every built-in problem).

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

STOP = frozenset({"mcfbench.running.schemes", "mcfbench.running.problems", "mcfbench.problems"})
"""The listings: not followed where they are imported (module docstring)."""

PROBLEM_DEFINITIONS = ("mcfbench.running.problems",)
"""The module defining ``Problem`` and the metrics: a root of every problem."""


def _module_of(qualified):
    """``"a.b"`` of ``"a.b:Name"``."""
    return qualified.partition(":")[0]


def scheme_roots(scheme):
    """The modules of ``scheme`` (a registry name, ``NAME@INTEGRATOR`` included):
    its flow's and, for another integrator than Euler, the integrator's."""
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import get_scheme

    entry = get_scheme(scheme)
    roots = [_module_of(entry.flow)]
    if entry.integrator != "euler":
        roots.append(INTEGRATORS[entry.integrator].__module__)
    return tuple(roots)


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
    """The data files ``problem`` reads: its ``data_files`` where it has them, else
    for a committed real mesh (``surface == "real_mesh"``) the mesh file and its
    reference answers and surface (:mod:`mcfbench.running.real_mesh_problems`);
    none for a generated surface."""
    files = getattr(problem, "data_files", None)
    if files is not None:
        return tuple(files)
    if problem.surface != "real_mesh":
        return ()
    from mcfbench.geometry.committed_meshes import MESH_DIR, mesh_manifest
    from mcfbench.running.real_mesh_problems import reference_path, surface_path

    name = problem.params(problem.levels[0])["mesh"]
    files = [MESH_DIR / mesh_manifest()[name]["file"], reference_path(name)]
    return tuple(files + [p for p in (surface_path(name),) if p.is_file()])


def _packages(roots):
    """The repository's packages and the outside ones ``roots`` lie in."""
    outside = sorted({r.split(".")[0] for r in roots} - set(code.REPOSITORY_PACKAGES))
    return (*code.REPOSITORY_PACKAGES, *outside)


@functools.cache
def _identity(roots, data):
    return code.code_identity(roots, _packages(roots), STOP, data)


@functools.cache
def _digest(scheme, problem):
    from mcfbench.running.problems import get_problem

    definition = get_problem(problem)
    roots = tuple(sorted({*HARNESS, *scheme_roots(scheme), *problem_roots(definition)}))
    identity = _identity(roots, problem_data(definition))
    return json.dumps(identity, sort_keys=True)


def run_identity(scheme, problem):
    """The code identity of a run of ``scheme`` (a registry name, ``NAME@INTEGRATOR``
    included) on ``problem`` (a registry name): a JSON-serialisable dict, its
    ``modules`` (path -> SHA-256), ``distributions`` (name -> version),
    ``unresolved``, ``data`` (path -> SHA-256) and ``python``
    (:func:`mcfbench.storage.code_identity.code_identity`); a fresh copy per call."""
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
    return identity_digest(_identity(roots, tuple(sorted(data))))


def forget_identities():
    """Forget every identity, file and version read (a test that changes them)."""
    _identity.cache_clear()
    _digest.cache_clear()
    code.clear_caches()
