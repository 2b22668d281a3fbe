"""The registry of problems: name -> :class:`~mcfbench.running.problem.Problem`.

The registry is found, not listed (:mod:`mcfbench.running.discovery`): the built-in
problems are the modules of :mod:`mcfbench.problems` (a module declares ``PROBLEM``
or ``PROBLEMS``, and optionally its ``surface`` generator and ``METRICS``
observers; their order is the modules' ``ORDER``: the sphere of Table 3.1, the
catenoid, the hemisphere, the torus, the dumbbell, Angenent's torus, Enneper's
patch, the real-world-like meshes the suite generates, then the committed real
meshes), then every installed package's entry points of the group
``mcfbench.problems``, sorted by name. Table 3.1 of the paper is the problem
``sphere`` run by the scheme ``ddfv``. A new problem is one file of
:mod:`mcfbench.problems` (and, if it needs one, a generator in
:mod:`mcfbench.geometry.surfaces` or its module's own ``surface``); a name declared
twice is an error naming both.
"""

import mcfbench.problems
from mcfbench.running.discovery import discover
from mcfbench.running import observers
from mcfbench.running.problem import KINDS, Problem, time_steps  # noqa: F401 (the API)

GROUP = "mcfbench.problems"
"""The entry-point group of installed packages' problems."""


def discover_problems(paths, package, group=None, registry=None):
    """Import every module of ``paths`` (a package's ``__path__``) as
    ``package.<name>``, then the entry points of ``group``, and register what they
    declare: their problems in ``registry`` (default :data:`PROBLEMS`), their modules'
    ``surface`` generators (:data:`mcfbench.geometry.surfaces.SURFACES`, unless a
    surface of that name exists) and ``METRICS`` observers
    (:data:`mcfbench.running.observers.METRICS`).

    Returns
    -------
    list of str
        The names of the problems registered.

    Raises
    ------
    mcfbench.running.discovery.RegistryError
        A module without ``PROBLEM`` or ``PROBLEMS``, or a problem name already in the
        registry (a ``ValueError``).
    """
    registry = PROBLEMS if registry is None else registry
    _, modules = discover(paths, package, "PROBLEM", "PROBLEMS", Problem, group, registry)
    for name, module in modules.items():
        if hasattr(module, "surface"):   # the surfaces' registry loads scipy: only then
            from mcfbench.geometry import surfaces

            surfaces.SURFACES.setdefault(registry[name].surface, module.surface)
        observers.METRICS.update(getattr(module, "METRICS", {}))
    return list(modules)


PROBLEMS = {}
"""Problem name -> :class:`Problem`, in the registry's order (module docstring)."""

discover_problems(mcfbench.problems.__path__, mcfbench.problems.__name__, GROUP)


def get_problem(name):
    """The registry entry ``name``.

    Raises
    ------
    ValueError
        Unknown name, listing the known ones.
    """
    try:
        return PROBLEMS[name]
    except KeyError:
        raise ValueError(f"unknown problem {name!r}; choose one of "
                         f"{', '.join(PROBLEMS)}") from None
