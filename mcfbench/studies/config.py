"""The one error of a bad config value, and the checks the studies share.

Every study checks its own config section in its ``plan``; a bad value raises
:class:`ConfigError` naming the key.
"""


class ConfigError(ValueError):
    """A config value the schema cannot check (a name against a registry, a time
    step, a level); the message names the key."""


def check_schemes(key, names):
    """``names`` as a list, every one a registry name or ``NAME@INTEGRATOR``
    (:func:`mcfbench.running.schemes.get_scheme`).

    Raises
    ------
    ConfigError
        Naming ``key``, the unknown names and every known scheme.
    """
    from mcfbench.running.integrators import INTEGRATORS
    from mcfbench.running.schemes import SCHEMES, find_scheme

    names = list(names)
    unknown = [s for s in names if find_scheme(s) is None]
    if unknown:
        raise ConfigError(f"config key {key!r}: unknown scheme(s) {unknown}; known schemes "
                          f"(mcfbench.running.schemes.SCHEMES): {', '.join(SCHEMES)}, each "
                          f"also as NAME@INTEGRATOR ({', '.join(INTEGRATORS)})")
    return names


def checked_steps(key, problem, tau, t_final, what):
    """``problem.time_steps(tau, t_final)``, its error as a ConfigError naming ``key``
    (``key`` quoted; two keys joined by `` and ``) and ``what`` time step it was."""
    try:
        return problem.time_steps(tau, t_final)
    except ValueError as err:
        raise ConfigError(f"config key{'s' if ' and ' in key else ''} {key}: {err} "
                          f"({what} time step)") from None


def check_rtol(key, value):
    """``value`` as a float in (0, 1) (the schema lets NaN through).

    Raises
    ------
    ConfigError
        Naming ``key``.
    """
    rtol = float(value)
    if not 0 < rtol < 1:
        raise ConfigError(f"config key {key!r}: must lie in (0, 1), got {value!r}")
    return rtol


def check_threads(config):
    """The config key ``threads`` (default 1): threads of every run job.

    Raises
    ------
    ConfigError
        Not a whole number >= 1.
    """
    threads = config.get("threads", 1)
    if isinstance(threads, bool) or not isinstance(threads, int) or threads < 1:
        raise ConfigError(f"config key 'threads': a whole number >= 1, got {threads!r}")
    return threads


def listed(value, every):
    """A config value naming several things: ``"all"`` (or None) for every one of
    ``every``, one name, or a list of names; as a list."""
    if value in ("all", None):
        return list(every)
    return [value] if isinstance(value, str) else list(value)


def check_mesh_runs(section, study, defaults=None):
    """The settings of a study that runs every scheme on mesh files for a number of
    steps (the gallery, the survival study), each bad value named ``<study>.<key>``.

    Parameters
    ----------
    section : dict or None
        ``schemes`` ("all" or names, :func:`check_schemes`), ``C`` (``tau = C (mean
        edge length)^2``), ``steps``, ``solver`` (a method of
        :data:`mcfbench.running.solver.METHODS` or ``"robust"``,
        :data:`mcfbench.running.solver.ROBUST`), ``rtol``, ``maxiter``.
    study : str
    defaults : dict, optional
        Defaults of those keys (otherwise every scheme, ``C`` 0.1, 40 steps, the
        robust solver, ``rtol`` 1e-9, ``maxiter`` 1000).

    Returns
    -------
    dict
        ``schemes`` (list), ``C``, ``steps``, ``solver`` (the method), ``rtol``, ``maxiter``.

    Raises
    ------
    ConfigError
    """
    from mcfbench.running import solver as _solver
    from mcfbench.running.schemes import SCHEMES

    section = {"schemes": "all", "C": 0.1, "steps": 40, "solver": "robust", "rtol": 1e-9,
               "maxiter": 1000, **(defaults or {}), **(section or {})}
    chosen = check_schemes(f"{study}.schemes", listed(section["schemes"], SCHEMES))
    method = _solver.ROBUST if section["solver"] == "robust" else section["solver"]
    if method not in _solver.METHODS:
        raise ConfigError(f"config key '{study}.solver': unknown solver {method!r}; choose "
                          f"one of {', '.join(_solver.METHODS)} or robust")
    C, steps = float(section["C"]), int(section["steps"])
    if not C > 0:
        raise ConfigError(f"config key '{study}.C': must be > 0, got {C!r}")
    if steps < 1:
        raise ConfigError(f"config key '{study}.steps': must be >= 1, got {steps!r}")
    return {"C": C, "steps": steps, "solver": method,
            "rtol": check_rtol(f"{study}.rtol", section["rtol"]),
            "maxiter": int(section["maxiter"]), "schemes": chosen}

