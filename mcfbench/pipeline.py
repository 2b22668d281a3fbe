"""The Snakemake glue: the checks of the whole config, the studies' plans, resources.

The workflow (``Snakefile``, ``workflow/rules/*.smk``) holds target lists and
input functions only; its scripts (``workflow/scripts/*.py``) are thin
adapters that call the study modules (:mod:`mcfbench.studies`). This module is
what the rules need beside them:

Config
    :func:`check_config` checks the whole config while Snakemake reads the
    workflow. Each study checks its own section (its schema, then its
    ``plan``) through :class:`Plans` (one generic entry, :meth:`Plans.plan`):
    those of Table 3.1 and of the beyond
    study only when a rule that needs them is in the job graph, those of the
    matrix and the gallery while Snakemake reads their rule files (their rules
    are made from them; a bad section leaves them without rules). A bad value
    stops only the study's own target, with a
    :class:`~mcfbench.studies.config.ConfigError` naming the key: a bad
    ``beyond`` value stops ``snakemake beyond``, not the matrix. In the workflow
    (:class:`WorkflowPlans`, :func:`message_only`) the message is printed without
    a traceback.
Settings
    Everything that determines one run record (scheme, problem, level, tau,
    t_final, solver tolerance, the source hash of every package): passed to
    the job, stored and hashed in the record, and recomputed by the
    aggregation to refuse stale records (:func:`mcfbench.storage.records.read_record`).
Resources
    :func:`mem_mb`, :func:`runtime_minutes` (generous, for Slurm).
Kernels
    :func:`compile_job` (rule ``compile_kernels``) fills numba's cache before
    the run jobs start.
"""

import hashlib
import importlib
import json
import math
import re
import time
from contextlib import contextmanager
from functools import wraps
from pathlib import Path

from mcfbench.running.identity import registry_identity
from mcfbench.running.problems import get_problem
from mcfbench.running.schemes import SCHEMES
from mcfbench.storage.atomic import write_json
from mcfbench.studies.config import ConfigError, check_threads
from mcfbench.studies.convergence.plan import PROBLEM


def check_config(config, schema_path):
    """Check the whole config against its schema (``schema_path``; its defaults
    filled in): unknown top-level keys in one line, naming them and the known ones,
    then the first bad value named by its key (Snakemake's schema check would print
    the whole schema after either).

    Raises
    ------
    ConfigError
    """
    import yaml

    known = yaml.safe_load(Path(schema_path).read_text())["properties"]
    unknown = sorted(set(config) - set(known))
    if unknown:
        raise ConfigError(f"unknown config key(s) {unknown}; known keys: "
                          f"{', '.join(sorted(known))} (config/README.md)")
    _validate(config, schema_path, [])


def check_section(config, key, schema_path):
    """Validate the config section ``key`` against its own schema (``schema_path``;
    its defaults filled in), as :func:`check_config` the whole config.

    Raises
    ------
    ConfigError
        Naming the key of the first bad value (``beyond.time_study.taus``) and
        what is wrong with it.
    """
    if config.get(key) is None:        # left out: the plan's own defaults
        return
    _validate(config[key], schema_path, [key])


def _validate(data, schema_path, where):
    """Snakemake's schema check of ``data`` (defaults filled in), its error as a
    ConfigError naming the key below ``where`` (a list of keys)."""
    from jsonschema.exceptions import ValidationError
    from snakemake.exceptions import WorkflowError
    from snakemake.utils import validate

    try:
        validate(data, str(schema_path))
    except WorkflowError as err:
        cause = err.__context__          # Snakemake raises it while handling jsonschema's
        if not isinstance(cause, ValidationError):
            raise
        key = ".".join([*where, *(str(p) for p in cause.absolute_path)])
        raise ConfigError(f"config key {key!r}: {cause.message} (schema "
                          f"{schema_path})") from None


@contextmanager
def message_only():
    """In the workflow: a :class:`~mcfbench.studies.config.ConfigError` ends
    Snakemake with its message alone (exit status 1).

    Snakemake prints an error raised while it reads the Snakefile with the lines
    of its traceback, and wraps one of an input function in an
    ``InputFunctionException`` with a traceback; ``SystemExit`` is not an
    ``Exception``, so neither catches it: Python prints its message to standard
    error and exits.
    """
    try:
        yield
    except ConfigError as err:
        raise SystemExit(f"ConfigError: {err}") from None


class WorkflowPlans:
    """:class:`Plans` for the rules (``PLANS`` of ``workflow/rules/common.smk``): its
    attributes and methods, with a ConfigError turned into a message without
    traceback (:func:`message_only`)."""

    def __init__(self, config, schemas):
        with message_only():
            self._plans = Plans(config, schemas)

    def __getattr__(self, name):
        with message_only():
            value = getattr(self._plans, name)
        if not callable(value):
            return value

        @wraps(value)
        def checked(*args, **kwargs):
            with message_only():
                return value(*args, **kwargs)
        return checked


def alternatives(names):
    """A wildcard constraint matching exactly ``names`` (longest first)."""
    return "|".join(re.escape(n) for n in sorted(names, key=len, reverse=True))


def scheme_pattern():
    """The wildcard constraint of a scheme: a registry name (longest first),
    optionally ``@<integrator>`` (:func:`mcfbench.running.schemes.get_scheme`)."""
    from mcfbench.running.integrators import INTEGRATORS

    return f"(?:{alternatives(SCHEMES)})(?:@(?:{alternatives(INTEGRATORS)}))?"


class Plans:
    """The plans of the studies for one config, each made (and its config section
    checked) on first use: those of Table 3.1 and of the beyond study when a rule
    that needs them joins the job graph, those of the matrix and the gallery while
    Snakemake reads their rule files (:meth:`while_reading`).

    A study is a folder of :mod:`mcfbench.studies` whose ``plan`` module has
    ``from_config(config, plans)``; its section of the config (when the study has
    one) is first checked against ``<schemas>/<study>.schema.yaml``. What a rule
    needs of a plan (settings of a run, record paths) is a function of the study's
    ``plan`` module, called by its ``workflow/rules/<study>.smk``.

    Parameters
    ----------
    config : dict
        Snakemake's config after the schema check (``config.schema.yaml``).
    schemas : str or Path
        The folder of the schemas (``workflow/schemas``).
    """

    def __init__(self, config, schemas):
        self.config = config
        self.schemas = Path(schemas)
        # the code of every run the registries make (not the studies' presentation)
        self.code = registry_identity()
        # threads of every run job and of the kernels' job: checked at once
        self.threads = check_threads(config)
        self._plans = {}

    @property
    def kernels(self):
        """The output of the kernels' compile job, named by the code it compiled:
        ``results/logs/kernels/<digest of the code>.json`` (:attr:`code`). A code change is a
        new file, so the run jobs that take it as input wait for the new compilation
        and run in the same invocation (with the code in the job's params instead,
        Snakemake reran only the compile job and reported the target done)."""
        digest = hashlib.sha256(json.dumps(self.code, sort_keys=True).encode()).hexdigest()
        return f"results/logs/kernels/{digest[:16]}.json"

    def plan(self, study):
        """The plan of ``study`` (``"convergence"``, ``"beyond"``, ``"matrix"``,
        ``"gallery"``): its section checked against its schema, then
        ``mcfbench.studies.<study>.plan.from_config``; made once.

        Raises
        ------
        ConfigError
            Naming the key of the first bad value.
        """
        if study not in self._plans:
            module = importlib.import_module(f"mcfbench.studies.{study}.plan")
            schema = self.schemas / f"{study}.schema.yaml"
            if schema.is_file():
                check_section(self.config, study, schema)
            self._plans[study] = module.from_config(self.config, self)
        return self._plans[study]

    def checked(self, study, targets):
        """``targets`` once the plan of ``study`` is made: the input of the study's
        target rule, so that a bad config value stops there with the
        :class:`~mcfbench.studies.config.ConfigError` naming it."""
        self.plan(study)
        return targets

    def while_reading(self, study, empty):
        """The plan of ``study`` (``"matrix"``, ``"gallery"``) for the rules made from
        it while Snakemake reads the workflow, or ``empty`` when its config section is
        bad: then the study has no rules and :meth:`checked` names the bad key when
        its target is asked for."""
        try:
            return self.plan(study)
        except ConfigError:
            return empty


# -- resources of the jobs (minutes, MB) ----------------------------------------------


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


# -- the kernels ---------------------------------------------------------------------


def warm_kernels(threads=1):
    """Compile every kernel, or load it from numba's cache when it is there.

    One level-1 sphere step of every scheme of the registry, on one thread
    and on ``threads`` when more (the threaded copies), one small solve
    with every solver method, for a shared and a coupled matrix, and the steady-state
    problems' speed (:func:`mcfbench.geometry.metrics.max_speed`; not a sphere's).
    """
    import numpy as np
    import scipy.sparse as sp

    from mcfbench.geometry.metrics import max_speed
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
    max_speed(np.zeros((2, 3)), np.ones((2, 3)), 1.0)      # two rows: Fortran order


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
