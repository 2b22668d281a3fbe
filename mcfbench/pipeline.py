"""The Snakemake pipeline's logic: config checks, run settings, targets, jobs.

The workflow (``Snakefile``, ``workflow/rules/*.smk``) holds target lists
and input functions only; its scripts (``workflow/scripts/*.py``) are thin
adapters that read Snakemake's inputs and params and call this module (or
:mod:`mcfbench.presentation.formats`, :mod:`mcfbench.presentation.plots`, :mod:`mcfbench.presentation.report`).

Config
    :class:`Pipeline` checks the config (after the schema,
    ``workflow/schemas/config.schema.yaml``) across keys while Snakemake
    reads the workflow: every scheme name is one of the registry
    :data:`mcfbench.running.schemes.SCHEMES`, every final time a whole multiple of
    its time steps. A bad value raises :class:`ConfigError` naming the key.
Settings
    Everything that determines one run record (scheme, problem, level, tau,
    t_final, solver tolerance, the source hash of every package): passed to
    the job, stored and hashed in the record, and recomputed by the
    aggregation to refuse stale records (:func:`mcfbench.storage.records.read_record`).
Jobs
    :func:`run_job`, :func:`time_job` run flows;
    :func:`record_fields` says what the aggregations check in a record.
"""

import math
import re
import time
from pathlib import Path

from mcfbench.running.problems import get_problem
from mcfbench.running.schemes import SCHEMES, get_scheme
from mcfbench.running.solver import Solver
from mcfbench.storage.atomic import write_json
from mcfbench.storage.provenance import code_hash
from mcfbench.storage.records import FIELDS, write_record
from mcfbench.studies.config import ConfigError

PROBLEM = "sphere"        # the problem of Table 3.1 and of the beyond study


# -- the config ---------------------------------------------------------------------

def check_schemes(key, names):
    """``names`` as a list, every one a registry name.

    Raises
    ------
    ConfigError
        Naming ``key``, the unknown names and every known scheme.
    """
    names = list(names)
    unknown = [s for s in names if s not in SCHEMES]
    if unknown:
        raise ConfigError(f"config key {key!r}: unknown scheme(s) {unknown}; known schemes "
                          f"(mcfbench.running.schemes.SCHEMES): {', '.join(SCHEMES)}")
    return names


def _steps(key, problem, tau, t_final, what):
    """``problem.time_steps``, its error as a ConfigError naming ``key``."""
    try:
        return problem.time_steps(tau, t_final)
    except ValueError as err:
        raise ConfigError(f"config key{'s' if ' and ' in key else ''} {key}: {err} "
                          f"({what} time step)") from None


def beyond_settings(config, problem):
    """Check ``config["beyond"]`` against the other keys and normalise it.

    Parameters
    ----------
    config : dict
        The whole config, already checked against the schema.
    problem : mcfbench.running.problems.Problem
        The sphere with the config's ``tau_level_1`` and ``t_final``.

    Returns
    -------
    dict
        ``levels`` (sorted ints), ``schemes``, ``finest`` (``level``,
        ``rtol`` of its runs, ``schemes``: the schemes whose rows of the
        L2/EOC table go on to that level; none by default), ``long_time`` (``level``, ``t_final``,
        ``tau``, ``schemes``), ``time_study`` (``level``, ``taus``
        (descending), ``reference_factor``, ``t_final``, ``schemes``) and
        ``space_study`` (``levels``, ``tau``, ``t_final``, ``schemes``); times
        as floats.

    Raises
    ------
    ConfigError
        An unknown scheme, a final time that is not a whole multiple of a
        time step, a scheme of ``beyond.finest`` that is not one of
        ``beyond.schemes``, or a finest level that is not above
        ``beyond.levels``; the message names the key.
    """
    beyond = config["beyond"]
    t_final = problem.t_final
    levels = sorted({int(level) for level in beyond["levels"]})
    for level in levels:
        _steps("'beyond.levels'", problem, problem.tau(level), t_final, f"the level-{level}")
    schemes = check_schemes("beyond.schemes", beyond["schemes"])
    finest = {"level": int(beyond["finest"]["level"]),
              "rtol": float(beyond["finest"].get("rtol", config["rtol"])),
              "schemes": check_schemes("beyond.finest.schemes", beyond["finest"]["schemes"])}
    if not 0 < finest["rtol"] < 1:          # the schema lets NaN through
        raise ConfigError(f"config key 'beyond.finest.rtol': must lie in (0, 1), got "
                          f"{beyond['finest']['rtol']!r}")
    if finest["schemes"]:
        _check_finest(finest, levels, schemes, problem)
    long, time_, space = beyond["long_time"], beyond["time_study"], beyond["space_study"]
    long_level, long_t = int(long["level"]), float(long["t_final"])
    _steps("'beyond.long_time.t_final'", problem, problem.tau(long_level), long_t,
           f"the level-{long_level}")
    taus = sorted({float(tau) for tau in time_["taus"]}, reverse=True)
    time_t = float(time_.get("t_final", t_final))
    for tau in taus:
        _steps("'beyond.time_study.taus'", problem, tau, time_t, "a")
    factor = int(time_["reference_factor"])
    _steps("'beyond.time_study.reference_factor'", problem, taus[-1] / factor, time_t,
           "the reference's")
    space_tau, space_t = float(space["tau"]), float(space.get("t_final", t_final))
    _steps("'beyond.space_study.tau'", problem, space_tau, space_t, "the")
    return {
        "levels": levels,
        "schemes": schemes,
        "finest": finest,
        "long_time": {"level": long_level, "t_final": long_t, "tau": problem.tau(long_level),
                      "schemes": check_schemes("beyond.long_time.schemes", long["schemes"])},
        "time_study": {"level": int(time_["level"]), "taus": taus, "reference_factor": factor,
                       "t_final": time_t,
                       "schemes": check_schemes("beyond.time_study.schemes",
                                                time_["schemes"])},
        "space_study": {"levels": sorted({int(level) for level in space["levels"]}),
                        "tau": space_tau, "t_final": space_t,
                        "schemes": check_schemes("beyond.space_study.schemes",
                                                 space["schemes"])},
    }


def _check_finest(finest, levels, schemes, problem):
    """``beyond.finest`` extends rows of the L2/EOC table: its schemes are some of
    ``schemes``, its level is above ``levels`` and its time step divides t_final."""
    others = [s for s in finest["schemes"] if s not in schemes]
    if others:
        raise ConfigError(f"config key 'beyond.finest.schemes': {others} not in "
                          f"'beyond.schemes' {schemes} (the finest level continues their "
                          "rows of the L2/EOC table)")
    level = finest["level"]
    if level <= levels[-1]:
        raise ConfigError(f"config key 'beyond.finest.level': {level} is not above the "
                          f"levels of 'beyond.levels' {levels}")
    _steps("'beyond.finest.level'", problem, problem.tau(level), problem.t_final,
           f"the level-{level}")


def used_schemes(beyond):
    """Every scheme the beyond study runs, in order of first appearance."""
    names = list(beyond["schemes"])
    for key in ("long_time", "time_study", "space_study"):
        names += [s for s in beyond[key]["schemes"] if s not in names]
    return names


def run_seconds(level, steps):
    """Rough single-core wall time of a run of ``steps`` steps on ``level``, with
    margin (10-13 ms a step on level 5, x4 per level, plus about 0.6 ms a step of
    fixed cost; up to 1.5x that with other jobs running)."""
    return steps * (0.02 * 4.0 ** (int(level) - 5) + 0.001)


def runtime_minutes(level, steps):
    """Slurm time limit in minutes: 4x :func:`run_seconds`, at least 5."""
    return max(5, math.ceil(4 * run_seconds(level, steps) / 60))


def mem_mb(level):
    """Peak memory with margin (level 5 about 95 MB, x4 per level)."""
    return 500 + 100 * 4 ** max(int(level) - 5, 0)


def alternatives(names):
    """A wildcard constraint matching exactly ``names`` (longest first)."""
    return "|".join(re.escape(n) for n in sorted(names, key=len, reverse=True))


def check_keys(config, schema_path):
    """Refuse unknown top-level config keys in one line, naming them and the known
    ones (Snakemake's schema check would print the whole schema after it)."""
    import yaml

    known = yaml.safe_load(Path(schema_path).read_text())["properties"]
    unknown = sorted(set(config) - set(known))
    if unknown:
        raise ConfigError(f"unknown config key(s) {unknown}; known keys: "
                          f"{', '.join(sorted(known))} (config/README.md)")


class Pipeline:
    """The checked config and everything derived from it.

    Parameters
    ----------
    config : dict
        Snakemake's config after the schema check (``--config levels=[1,2]``
        gives strings: normalised here).

    Raises
    ------
    ConfigError
        See :func:`check_schemes`, :func:`beyond_settings`, and a ``t_final``
        that is not a whole multiple of every level's time step.
    """

    def __init__(self, config):
        self.levels = sorted({int(level) for level in config["levels"]})
        self.schemes = check_schemes("schemes", config["schemes"])
        self.rtol = float(config["rtol"])
        if not 0 < self.rtol < 1:          # the schema lets NaN through
            raise ConfigError(f"config key 'rtol': must lie in (0, 1), got {config['rtol']!r}")
        self.threads = config.get("threads", 1)
        if isinstance(self.threads, bool) or not isinstance(self.threads, int) \
                or self.threads < 1:
            raise ConfigError(f"config key 'threads': a whole number >= 1, got "
                              f"{self.threads!r}")
        self.problem = get_problem(PROBLEM).with_settings(
            tau_1=float(config["tau_level_1"]), t_final=float(config["t_final"]))
        for level in self.levels:
            _steps("'t_final' and 'tau_level_1'", self.problem, self.problem.tau(level),
                   self.problem.t_final, f"the level-{level}")
        self.beyond = beyond_settings(config, self.problem)
        self.config = {**config, "levels": self.levels}
        self.code = code_hash()

    # -- settings of one record
    def run_settings(self, scheme, level, *, study=None, tau=None, t_final=None):
        """Everything that determines the run record of (scheme, level).

        ``study``, ``tau`` and ``t_final`` override the convergence study's
        settings (the studies beyond Table 3.1); without them the settings,
        and so the hash, are those of Table 3.1.
        """
        level = int(level)
        finest = self.beyond["finest"]
        # the finest level's runs of beyond.finest: their own tolerance (config/README.md)
        rtol = finest["rtol"] if study is None and level == finest["level"] \
            and scheme in finest["schemes"] else self.rtol
        settings = {"scheme": scheme, "problem": self.problem.name, "level": level,
                    "tau": self.problem.tau(level) if tau is None else float(tau),
                    "t_final": self.problem.t_final if t_final is None else float(t_final),
                    "rtol": rtol, "threads": self.threads, "code": self.code}
        return settings if study is None else {"study": study, **settings}

    def beyond_run_settings(self, study, scheme, level):
        """Settings of one run of the long-time or the space study."""
        if study == "long_time":
            return self.run_settings(scheme, level, study=study,
                                     t_final=self.beyond["long_time"]["t_final"])
        space = self.beyond["space_study"]
        return self.run_settings(scheme, level, study=study, tau=space["tau"],
                                 t_final=space["t_final"])

    def time_settings(self, scheme):
        """Settings of the time study of one scheme."""
        study = self.beyond["time_study"]
        return {"study": "time", "scheme": scheme, "problem": self.problem.name,
                "level": study["level"], "taus": study["taus"],
                "reference_factor": study["reference_factor"], "t_final": study["t_final"],
                "rtol": self.rtol, "threads": self.threads, "code": self.code}

    def convergence_settings(self):
        """The config as far as Table 3.1 depends on it (not the other studies)."""
        return {k: self.config[k] for k in ("levels", "schemes", "tau_level_1", "t_final",
                                            "rtol")}

    # -- record paths and targets
    @staticmethod
    def run_record(scheme, level):
        return f"results/runs/{scheme}/level{level}.json"

    def run_records(self):
        """Run records of every (scheme, level), schemes in config order."""
        return [self.run_record(s, level) for s in self.schemes for level in self.levels]

    def expected_runs(self):
        """``{record path: settings}`` of the convergence study."""
        return {self.run_record(s, lv): self.run_settings(s, lv)
                for s in self.schemes for lv in self.levels}

    def beyond_levels(self, scheme):
        """Levels of ``scheme`` in the L2/EOC table: ``beyond.levels``, and
        ``beyond.finest.level`` for the schemes of ``beyond.finest``."""
        finest = self.beyond["finest"]
        return self.beyond["levels"] + ([finest["level"]] if scheme in finest["schemes"]
                                        else [])

    def beyond_runs(self):
        """``{study: {record path: settings}}`` of the beyond study."""
        b = self.beyond
        return {
            "levels": {self.run_record(s, lv): self.run_settings(s, lv)
                       for s in b["schemes"] for lv in self.beyond_levels(s)},
            "long_time": {
                f"results/beyond/runs/long_time/{s}/level{b['long_time']['level']}.json":
                    self.beyond_run_settings("long_time", s, b["long_time"]["level"])
                for s in b["long_time"]["schemes"]},
            "space": {f"results/beyond/runs/space/{s}/level{lv}.json":
                      self.beyond_run_settings("space", s, lv)
                      for s in b["space_study"]["schemes"] for lv in b["space_study"]["levels"]},
            "time": {f"results/beyond/runs/time/{s}.json": self.time_settings(s)
                     for s in b["time_study"]["schemes"]},
        }

    def paper_schemes(self):
        """Schemes of the beyond study compared with the published Table 3.1: the DDFV ones."""
        return [s for s in self.beyond["schemes"] if get_scheme(s).family == "ddfv"]

    @staticmethod
    def scheme_pattern():
        """Regular expression of the registry's names, longest first."""
        return alternatives(SCHEMES)

    # -- resources of the jobs (minutes, MB)
    @staticmethod
    def mem_mb(level):
        return mem_mb(level)

    def run_runtime(self, level):
        return runtime_minutes(level, self.problem.time_steps(self.problem.tau(int(level))))

    def beyond_runtime(self, study, scheme, level):
        settings = self.beyond_run_settings(study, scheme, level)
        return runtime_minutes(level, round(settings["t_final"] / settings["tau"]))

    def time_runtime(self):
        study = self.beyond["time_study"]
        steps = sum(round(study["t_final"] / tau) for tau in study["taus"])
        steps += round(study["t_final"] * study["reference_factor"] / study["taus"][-1])
        return runtime_minutes(study["level"], steps)


# -- jobs --------------------------------------------------------------------------

def solver_of(settings):
    """The shared solver with the settings' tolerance (``maxiter``, ``threads`` if given)."""
    return Solver(rtol=settings["rtol"], **{k: settings[k] for k in ("maxiter", "threads")
                                            if k in settings})


def run_job(settings, output, log):
    """One scheme on one level of the problem with ``settings``: its run record.

    Returns
    -------
    mcfbench.storage.records.RunResult
    """
    from mcfbench.running.run import run

    problem = get_problem(settings["problem"]).with_settings(t_final=settings["t_final"])
    log.info("%s level %d: tau %g, t_final %g, rtol %g", settings["scheme"], settings["level"],
             settings["tau"], settings["t_final"], settings["rtol"])
    result, _ = run(settings["scheme"], problem, settings["level"], tau=settings["tau"],
                    t_final=settings["t_final"], solver=solver_of(settings),
                    threads=settings.get("threads", 1))
    record = write_record(output, result, settings)
    log.info("%s level %d: status %s, L2 error %.4e, %d iterations, %.3f s wall, "
             "%.0f MB peak memory -> %s", result.scheme, result.level, result.status,
             result.metrics.get("l2_error", math.nan), result.iterations, result.wall_seconds,
             record["peak_rss_mb"], output)
    if result.status != "ok":
        log.warning("%s", result.message)
    return result


def warm_kernels(threads=1):
    """Compile every kernel, or load it from numba's cache when it is there.

    One level-1 sphere step of every scheme of the registry, on one thread
    and on ``threads`` when more (the threaded copies), and one small solve
    with every solver method, for a shared and a coupled matrix.
    """
    import numpy as np
    import scipy.sparse as sp

    from mcfbench.running.run import run
    from mcfbench.running.solver import METHODS, solve

    problem = get_problem(PROBLEM)
    for name in SCHEMES:
        for n in sorted({1, threads}):
            run(name, problem, 1, t_final=problem.tau(1), threads=n)
    n = 30
    A = sp.diags([-np.ones(n - 1), 4.0 * np.ones(n), -np.ones(n - 1)], [-1, 0, 1],
                 format="csr")
    b = np.ones((3, n))
    for method in METHODS:
        solve(A, b, None, method=method)
        solve(sp.kron(sp.eye(3), A, format="csr"), b, None, method=method)


def compile_job(threads, output, log):
    """Compile every kernel into numba's cache once, before the run jobs start
    (:func:`warm_kernels`).

    The run jobs then load the kernels from the cache instead of each
    compiling them (numba writes its cache files by rename: jobs that start
    together on an empty cache would each compile, never corrupt it;
    ``tests/workflow/test_pipeline.py``). Writes the seconds it took (compiling, or
    loading when the cache was warm) to ``output``.
    """
    from mcfbench.running.solver import METHODS

    start = time.perf_counter()
    warm_kernels(threads)
    seconds = time.perf_counter() - start
    write_json(output, {"seconds": seconds, "threads": threads, "schemes": list(SCHEMES),
                        "methods": list(METHODS)})
    log.info("kernels of %d schemes and %d solver methods compiled or loaded in %.1f s -> %s",
             len(SCHEMES), len(METHODS), seconds, output)


TIME_FIELDS = {"scheme": str, "level": int, "reference_tau": float, "t_final": float,
               "outcome": str, "message": str, "rows": list, "wall_seconds": float,
               "peak_rss_mb": float, "settings": dict, "provenance": dict, "checksum": str}
"""Key -> type of a time-study record (:func:`time_job`)."""


def time_job(settings, output, log):
    """Time convergence of one scheme on one mesh (:func:`mcfbench.running.run.time_convergence`).

    A reference run that breaks down does not fail the job: the record has
    ``outcome = "reference_failed"``, the message and no rows; single runs
    that break down are rows with their status.
    """
    from mcfbench.running.run import time_convergence

    problem = get_problem(settings["problem"]).with_settings(t_final=settings["t_final"])
    taus, factor = settings["taus"], settings["reference_factor"]
    log.info("%s level %d: time_convergence(taus=%s, reference_factor=%d, t_final=%g, "
             "rtol=%g)", settings["scheme"], settings["level"], taus, factor,
             settings["t_final"], settings["rtol"])
    wall = time.perf_counter()
    try:
        table = time_convergence(settings["scheme"], problem, settings["level"], taus,
                                 reference_factor=factor, t_final=settings["t_final"],
                                 solver=solver_of(settings),
                                 threads=settings.get("threads", 1))
        rows, outcome, message = table.to_dict("records"), "ok", ""
    except RuntimeError as err:
        rows, outcome, message = [], "reference_failed", str(err)
    wall = time.perf_counter() - wall
    record = write_record(output, {"scheme": settings["scheme"], "level": settings["level"],
                                   "taus": taus, "reference_factor": factor,
                                   "reference_tau": min(taus) / factor,
                                   "t_final": settings["t_final"], "outcome": outcome,
                                   "message": message, "rows": rows, "wall_seconds": wall},
                          settings)
    log.info("%s: %s in %.1f s, %.0f MB peak memory -> %s", settings["scheme"], outcome, wall,
             record["peak_rss_mb"], output)
    if outcome != "ok":
        log.warning("%s", message)
    for row in rows:
        log.info("tau %-10g error %.4e eoc %.3f %s", row["tau"], row["error"], row["eoc"],
                 row["status"])


def record_fields(settings):
    """The keys and types a record of ``settings`` must have (``required`` of
    :func:`mcfbench.storage.records.read_records`): the time study's records
    have their own (:data:`TIME_FIELDS`), every other run record :data:`FIELDS`."""
    return TIME_FIELDS if settings.get("study") == "time" else FIELDS
