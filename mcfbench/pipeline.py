"""The Snakemake glue: the checks of the whole config, the studies' plans, resources.

The workflow (``Snakefile``, ``workflow/rules/*.smk``) holds target lists and
input functions only; its scripts (``workflow/scripts/*.py``) are thin
adapters that call the study modules (:mod:`mcfbench.studies`). This module is
what the rules need beside them:

Config
    :func:`check_config` checks the whole config while Snakemake reads the
    workflow. Each study checks its own section (its schema, then its
    ``plan``) through :class:`Plans` (one generic entry, :meth:`Plans.plan`):
    every study's while Snakemake reads the workflow, for the run store's batches
    (:class:`RunStore`; a bad section contributes no run and the study's views
    no rule's input is made of it). A bad value
    stops only the study's own target, with a
    :class:`~mcfbench.studies.config.ConfigError` naming the key: a bad
    ``beyond`` value stops ``snakemake beyond``, not the matrix. In the workflow
    (:class:`WorkflowPlans`, :func:`message_only`) the message is printed without
    a traceback.
Runs
    :class:`RunStore`: the specs of every study (:mod:`mcfbench.storage.run_store`,
    each study's ``plan.run_specs``), their code digests
    (:func:`mcfbench.running.identity.identity_digest`) and the batches of
    :func:`mcfbench.running.batching.batches`, made while Snakemake reads the
    workflow: the rules of ``workflow/rules/runs.smk`` and the studies' views'
    inputs (the batch manifests) and params (the specs and their digests).
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
import os
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

PROBLEM = "sphere"
"""The problem of the kernels' warm-up (:func:`warm_kernels`)."""

FRAMEWORK_RULES = ("common.smk", "kernels.smk", "runs.smk")
"""The rule files every study's builds on (the Snakefile includes them first)."""


def studies():
    """The studies: the folders of :mod:`mcfbench.studies` with a ``plan`` module, in
    name order. A new study is a folder there (and its rule file and config key):
    nothing here lists them."""
    import mcfbench.studies

    folder = Path(mcfbench.studies.__path__[0])
    return [p.name for p in sorted(folder.iterdir()) if (p / "plan.py").is_file()]


def section_studies():
    """The studies whose config section is the top-level key of their name: every study
    but one whose ``plan`` says ``SECTION = None`` (Table 3.1's keys are the config's
    top level)."""
    return [study for study in studies()
            if getattr(importlib.import_module(f"mcfbench.studies.{study}.plan"), "SECTION",
                       study) is not None]


def run_studies():
    """The studies whose runs the run store's shared batches make (their ``plan``
    module has ``run_specs(plans)``), in name order, but those whose ``plan`` says
    ``OWN_BATCHES``: their rule file makes their batches (the gallery's, one per mesh
    file, its specs made when a batch joins the job graph: they hash the meshes it
    generates, seconds, and Snakemake does not know the targets while it reads the
    workflow)."""
    chosen = []
    for study in studies():
        module = importlib.import_module(f"mcfbench.studies.{study}.plan")
        if hasattr(module, "run_specs") and not getattr(module, "OWN_BATCHES", False):
            chosen.append(study)
    return chosen


def study_rule_files(folder):
    """The rule files of ``folder`` (``workflow/rules``) but :data:`FRAMEWORK_RULES`,
    in name order: what the Snakefile includes after those."""
    return [str(p) for p in sorted(Path(folder).glob("*.smk")) if p.name not in FRAMEWORK_RULES]


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
    sections = section_studies()
    unknown = sorted(set(config) - set(known) - set(sections))
    if unknown:
        raise ConfigError(f"unknown config key(s) {unknown}; known keys: "
                          f"{', '.join(sorted({*known, *sections}))} (config/README.md)")
    # a study's section that the schema does not name is its plan's to check
    _validate({k: v for k, v in config.items() if k in known}, schema_path, [])


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


class Plans:
    """The plans of the studies for one config, each made (and its config section
    checked) on first use: while Snakemake reads the workflow, for the run store's
    batches (:class:`RunStore`) and the rules made from a plan (:meth:`while_reading`);
    a bad section is named when the study's target is asked for (:meth:`checked`).

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
        """The output of the kernels' compile job, named by the code it compiles:
        ``results/logs/kernels/<digest>.json``, the digest of the code identities of
        every scheme of the registry on every problem
        (:func:`mcfbench.running.identity.run_identity`). A change of a run's code is a
        new file, so the run jobs that take it as input wait for the new compilation
        and run in the same invocation (with the code in the job's params instead,
        Snakemake reran only the compile job and reported the target done); a change
        of no run's code (a table, a plot, the report) compiles nothing and reruns no
        batch."""
        from mcfbench.running.identity import identity_digest, run_identity
        from mcfbench.running.problems import PROBLEMS

        digests = sorted({identity_digest(run_identity(s, p)) for s in SCHEMES
                          for p in PROBLEMS})
        digest = hashlib.sha256(json.dumps(digests).encode()).hexdigest()
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


class RunStore:
    """The run store's plan for the workflow: the specs of every study of
    :func:`run_studies` whose section is good (a bad one contributes no spec; its
    target names the key, :meth:`Plans.checked`), gathered into batches.

    Parameters
    ----------
    plans : Plans or WorkflowPlans
    studies : sequence of str
        The studies planned (default :func:`run_studies`).
    """

    def __init__(self, plans, studies=None):
        from mcfbench.running.batching import batches

        self.requests = {}
        for study in run_studies() if studies is None else studies:
            module = importlib.import_module(f"mcfbench.studies.{study}.plan")
            try:
                self.requests[study] = list(module.run_specs(plans))
            except (ConfigError, SystemExit):       # SystemExit: WorkflowPlans' message
                continue
        self.batches = batches(self.requests)
        self._batch = {spec: batch for batch in self.batches for spec in batch.specs}
        self._digests = {}

    def digest(self, spec):
        """The code digest of a spec's run (:func:`code_digests`)."""
        if spec not in self._digests:
            self._digests.update(code_digests([spec]))
        return self._digests[spec]

    def entries(self, specs):
        """The params of a batch's job (its ``specs``): per spec its dict and code digest."""
        return [{"spec": spec.to_dict(), "code": self.digest(spec)} for spec in specs]

    def manifests(self, specs):
        """The manifests of the batches holding ``specs`` (a view's inputs), sorted."""
        from mcfbench.storage.run_store import manifest_path

        return sorted({manifest_path(self._batch[spec].name) for spec in specs})

    def expected(self, specs):
        """``[(spec dict, code digest)]`` of ``specs``: a view's params, read back
        by :func:`expected_runs`."""
        return [(spec.to_dict(), self.digest(spec)) for spec in specs]


def jobs_pythonpath(pythonpath=None):
    """``PYTHONPATH`` for the jobs: the folder holding the ``mcfbench`` that the
    workflow imported first, then ``pythonpath`` (the current value; that folder left
    out of it).

    Snakemake plans the runs, their code digests (a batch's params) included, with
    the packages it imports, the Snakefile's folder first on its import path; a job's
    script runs in another process, whose import path has neither. Without this,
    Snakemake run in a checkout whose ``PYTHONPATH`` does not name it plans with the
    checkout's code while its jobs run another copy (an editable install's): a batch
    is not rerun after an edit and the views' digests differ from the records' (a
    stale-record error), or a run computed by the other copy is recorded under the
    checkout's digest.

    Parameters
    ----------
    pythonpath : str, optional

    Returns
    -------
    str
    """
    import mcfbench

    root = Path(mcfbench.__file__).resolve().parents[1]
    rest = [p for p in (pythonpath or "").split(os.pathsep) if p and Path(p).resolve() != root]
    return os.pathsep.join([str(root), *rest])


def jobs_environment():
    """``{"PYTHONPATH": ...}`` for the Snakefile to set: :func:`jobs_pythonpath` of this
    process's."""
    return {"PYTHONPATH": jobs_pythonpath(os.environ.get("PYTHONPATH"))}


def code_digests(specs):
    """``{spec: code digest}``: the digest of each spec's run identity
    (:func:`mcfbench.running.identity.run_identity` of its scheme and problem), the
    current code's; what the run store's records must carry (a view's expected runs)."""
    from mcfbench.running.identity import identity_digest, run_identity

    digests = {}
    for name in {(spec.scheme, spec.problem) for spec in specs}:
        digests[name] = identity_digest(run_identity(*name))
    return {spec: digests[spec.scheme, spec.problem] for spec in specs}


def expected_runs(params):
    """``{RunSpec: code digest}`` of :meth:`RunStore.expected` (a view's params), for
    :func:`mcfbench.storage.run_store.read_runs`."""
    from mcfbench.storage.run_store import RunSpec

    return {RunSpec.from_dict(dict(spec)): digest for spec, digest in params}


def batch_resources(batch):
    """``(mem_mb, runtime minutes)`` of a batch's job: as a matrix batch's (1 500 MB,
    120 minutes), a gallery mesh's (2 000 MB, 60 minutes a scheme), or the
    generous bounds of its costliest run when they are more."""
    levels = [spec.level for spec in batch.specs]
    if batch.problem == "gallery":
        return 2000, 60 * len(batch.specs)
    steps = [spec.steps if spec.tau is None else round(spec.t_final / spec.tau)
             for spec in batch.specs]
    return (max(1500, *(mem_mb(level) for level in levels)),
            max(120, sum(runtime_minutes(level, n) for level, n in zip(levels, steps))))


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
