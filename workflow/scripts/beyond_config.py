"""The config key ``beyond``: checks across keys and its normal form.

Loaded by workflow/rules/common.smk (for the rules of
workflow/rules/beyond.smk) while Snakemake reads the workflow, after the
schema check of workflow/schemas/config.schema.yaml, so that a bad value
stops Snakemake before any job, with a message naming the key.
Plain Python without the repository's packages: importable by the tests.
"""

import math

# the module whose sphere_run is the DDFV scheme (time_convergence needs it)
DDFV_MODULE = "ddfv.sphere"


class ConfigError(ValueError):
    """A config value the schema cannot check; the message names the key."""


def _whole_steps(t_final, tau):
    """``t_final / tau`` when it is a whole number >= 1, else None."""
    steps = t_final / tau
    if steps < 0.5 or not math.isclose(steps, round(steps), rel_tol=1e-9):
        return None
    return round(steps)


def _check_steps(key, t_final, tau, what):
    if _whole_steps(t_final, tau) is None:
        raise ConfigError(f"config key {key!r}: t_final = {t_final:g} is not a whole "
                          f"multiple of {what} tau = {tau:g} (t_final / tau = "
                          f"{t_final / tau:g})")


def _schemes(key, names, scheme_modules, ddfv_only=False):
    names = list(names)
    unknown = [s for s in names if s not in scheme_modules]
    if unknown:
        raise ConfigError(f"config key {key!r}: unknown scheme(s) {unknown}; known schemes "
                          f"are the keys of 'scheme_modules': {sorted(scheme_modules)}")
    if ddfv_only:
        other = [s for s in names if scheme_modules[s][0] != DDFV_MODULE]
        if other:
            raise ConfigError(f"config key {key!r}: scheme(s) {other} are not DDFV schemes "
                              f"(module {DDFV_MODULE}); the time study runs "
                              "ddfv.convergence.time_convergence, which only knows those")
    return names


def beyond_settings(config, scheme_modules):
    """Check ``config["beyond"]`` against the other keys and normalise it.

    Parameters
    ----------
    config : dict
        The whole config, already checked against the schema.
    scheme_modules : dict
        ``scheme -> (module, options)`` (``SCHEME_MODULES`` of common.smk).

    Returns
    -------
    dict
        ``levels`` (sorted ints), ``schemes``, ``long_time`` (``level``,
        ``t_final``, ``tau``, ``schemes``), ``time_study`` (``level``,
        ``taus`` (descending), ``reference_factor``, ``t_final``,
        ``schemes``) and ``space_study`` (``levels``, ``tau``, ``t_final``,
        ``schemes``); times as floats.

    Raises
    ------
    ConfigError
        An unknown scheme, a non-DDFV scheme in the time study, or a final
        time that is not a whole multiple of a time step; the message names
        the key.
    """
    beyond = config["beyond"]
    tau_1, t_final = float(config["tau_level_1"]), float(config["t_final"])

    def level_tau(level):
        return tau_1 / 4.0 ** (level - 1)

    levels = sorted({int(level) for level in beyond["levels"]})
    for level in levels:
        _check_steps("beyond.levels", t_final, level_tau(level), f"the level-{level}")

    long = beyond["long_time"]
    long_level = int(long["level"])
    long_t = float(long["t_final"])
    _check_steps("beyond.long_time.t_final", long_t, level_tau(long_level),
                 f"the level-{long_level}")

    time = beyond["time_study"]
    taus = sorted({float(tau) for tau in time["taus"]}, reverse=True)
    time_t = float(time.get("t_final", t_final))
    for tau in taus:
        _check_steps("beyond.time_study.taus", time_t, tau, "the")
    factor = int(time["reference_factor"])
    _check_steps("beyond.time_study.reference_factor", time_t, taus[-1] / factor,
                 "the reference's")

    space = beyond["space_study"]
    space_tau = float(space["tau"])
    space_t = float(space.get("t_final", t_final))
    _check_steps("beyond.space_study.tau", space_t, space_tau, "the")

    return {
        "levels": levels,
        "schemes": _schemes("beyond.schemes", beyond["schemes"], scheme_modules),
        "long_time": {
            "level": long_level, "t_final": long_t, "tau": level_tau(long_level),
            "schemes": _schemes("beyond.long_time.schemes", long["schemes"], scheme_modules)},
        "time_study": {
            "level": int(time["level"]), "taus": taus, "reference_factor": factor,
            "t_final": time_t,
            "schemes": _schemes("beyond.time_study.schemes", time["schemes"], scheme_modules,
                                ddfv_only=True)},
        "space_study": {
            "levels": sorted({int(level) for level in space["levels"]}), "tau": space_tau,
            "t_final": space_t,
            "schemes": _schemes("beyond.space_study.schemes", space["schemes"],
                                scheme_modules)},
    }


def used_schemes(settings):
    """Every scheme the beyond study runs, in order of first appearance."""
    names = list(settings["schemes"])
    for key in ("long_time", "time_study", "space_study"):
        names += [s for s in settings[key]["schemes"] if s not in names]
    return names
