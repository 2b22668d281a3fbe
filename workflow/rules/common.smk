# Helpers shared by the rules: checks of the validated config that need more
# than one key, the settings of one run, and the target lists.

import functools
import hashlib
import importlib.util
import math
import os
import re
import sys
from pathlib import Path


class ConfigError(ValueError):
    """A config value the schema cannot check; the message names the key."""


# `--config levels=[1,2]` gives strings (checked by the schema): normalise
LEVELS = sorted({int(level) for level in config["levels"]})
config["levels"] = LEVELS
SCHEMES = list(config["schemes"])
# scheme -> (module, options of its sphere_run)
SCHEME_MODULES = {
    name: (entry, {}) if isinstance(entry, str) else (entry["module"], entry.get("options", {}))
    for name, entry in config["scheme_modules"].items()
}

_unknown = [s for s in SCHEMES if s not in SCHEME_MODULES]
if _unknown:
    raise ConfigError(
        f"config key 'schemes': unknown scheme(s) {_unknown}; known schemes are "
        f"the keys of 'scheme_modules': {sorted(SCHEME_MODULES)}"
    )


def level_time_step(level):
    """tau = tau_level_1 / 4**(level - 1), the coupling tau ~ h^2 of Table 3.1."""
    return float(config["tau_level_1"]) / 4.0 ** (level - 1)


def level_steps(level):
    """Number of time steps N = t_final / tau of a level."""
    return round(float(config["t_final"]) / level_time_step(level))


for _level in LEVELS:
    _steps = config["t_final"] / level_time_step(_level)
    if _steps < 0.5 or not math.isclose(_steps, round(_steps), rel_tol=1e-9):
        raise ConfigError(
            f"config keys 't_final' and 'tau_level_1': t_final = {config['t_final']} "
            f"is not a whole multiple of the level-{_level} time step "
            f"tau = {level_time_step(_level):g} (t_final / tau = {_steps:g})"
        )


def _package_dir(top):
    """Folder of package `top` as the jobs will import it: next to this
    Snakefile (a checkout; workflow/scripts/run_records.py puts that first on
    sys.path) or installed, editable installs included. The working
    directory does not count: scripts do not run with it on sys.path.
    None if not importable."""
    local = Path(workflow.basedir) / top / "__init__.py"
    if local.is_file():
        return local.parent
    saved = sys.path[:]
    sys.path[:] = [p for p in sys.path if p not in ("", os.getcwd())]
    try:
        spec = importlib.util.find_spec(top)
    finally:
        sys.path[:] = saved
    return Path(spec.origin).parent if spec is not None and spec.origin else None


def _check_importable(scheme, module):
    """Fail early unless the jobs can import `module` (see _package_dir)."""
    top = module.split(".")[0]
    if _package_dir(top) is None:
        raise ConfigError(
            f"config key 'scheme_modules.{scheme}': package {top!r} of module "
            f"{module!r} is not importable; install the project "
            "(pip install -e . in the repository) or put it on PYTHONPATH"
        )


for _scheme in SCHEMES:
    _check_importable(_scheme, SCHEME_MODULES[_scheme][0])


@functools.cache
def code_digest(top):
    """SHA-256 of the Python files of package `top`: part of the run settings,
    so that a run is redone when the code of its scheme changes (Snakemake
    tracks only the rule's own script)."""
    digest = hashlib.sha256()
    root = _package_dir(top)
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def run_settings(scheme, level, *, study=None, tau=None, t_final=None):
    """Everything that determines the run record of (scheme, level).

    Passed to the run job and stored (with its hash) in the record's
    provenance; the aggregation recomputes it to detect stale records.
    ``study``, ``tau`` and ``t_final`` override the convergence study's
    settings (the studies of workflow/rules/beyond.smk); without them the
    settings, and so the hash, are those of Table 3.1.
    """
    level = int(level)
    settings = {
        "scheme": scheme,
        "module": SCHEME_MODULES[scheme][0],
        "options": SCHEME_MODULES[scheme][1],
        "level": level,
        "tau": level_time_step(level) if tau is None else float(tau),
        "t_final": float(config["t_final"] if t_final is None else t_final),
        "radius": 1.0,
        "rtol": float(config["rtol"]),
        "code": {top: code_digest(top) for top in _packages(scheme)},
    }
    if study is not None:
        settings = {"study": study, **settings}
    return settings


def _packages(scheme):
    """The packages a run imports: ddfv (SphereRun, solver) and the scheme's."""
    return sorted({"ddfv", SCHEME_MODULES[scheme][0].split(".")[0]})


def run_record(scheme, level):
    return f"results/runs/{scheme}/level{level}.json"


def run_records():
    """Run records of every (scheme, level), schemes in config order."""
    return [run_record(s, level) for s in SCHEMES for level in LEVELS]


def expected_runs():
    """{record path: settings} for the aggregation's checks."""
    return {run_record(s, lv): run_settings(s, lv) for s in SCHEMES for lv in LEVELS}


def run_seconds_estimate(level):
    """Rough single-core wall time of one run (level 5: a few s; x16 per level)."""
    return 10.0 * 16.0 ** (int(level) - 5)


def run_runtime(wildcards):
    """Slurm time limit in minutes: 4x the estimate, at least 5."""
    return max(5, math.ceil(4 * run_seconds_estimate(wildcards.level) / 60))


def run_mem_mb(wildcards):
    """Peak memory with margin (measured: level 5 about 95 MB, x4 per level)."""
    return 500 + 100 * 4 ** max(int(wildcards.level) - 5, 0)


def convergence_settings():
    """The config as far as Table 3.1 depends on it: without the beyond study
    and with the modules of the schemes run, so that changing those leaves
    the tables of the convergence study alone."""
    settings = {k: v for k, v in config.items() if k != "beyond"}
    settings["scheme_modules"] = {s: config["scheme_modules"][s] for s in SCHEMES}
    return settings


# -- the study beyond Table 3.1 (workflow/rules/beyond.smk) --------------------


def _load_script(name):
    """A module of workflow/scripts by file (leaves sys.path alone)."""
    path = Path(workflow.basedir) / "workflow" / "scripts" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"_workflow_{name}", path)
    loaded = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(loaded)
    return loaded


_beyond_config = _load_script("beyond_config")
# the config key `beyond`, checked across keys and normalised
BEYOND = _beyond_config.beyond_settings(config, SCHEME_MODULES)
for _scheme in _beyond_config.used_schemes(BEYOND):
    _check_importable(_scheme, SCHEME_MODULES[_scheme][0])
# schemes compared with the published Table 3.1: the DDFV variants
BEYOND_PAPER_SCHEMES = [
    s for s in BEYOND["schemes"] if SCHEME_MODULES[s][0] == _beyond_config.DDFV_MODULE
]


def beyond_record(study, scheme, level):
    return f"results/beyond/runs/{study}/{scheme}/level{level}.json"


def time_record(scheme):
    return f"results/beyond/runs/time/{scheme}.json"


def beyond_run_settings(study, scheme, level):
    """Run settings of one run of the long-time or the space study."""
    if study == "long_time":
        return run_settings(scheme, level, study=study, t_final=BEYOND["long_time"]["t_final"])
    space = BEYOND["space_study"]
    return run_settings(scheme, level, study=study, tau=space["tau"], t_final=space["t_final"])


def time_settings(scheme):
    """Settings of the time study of one (DDFV) scheme."""
    study = BEYOND["time_study"]
    return {
        "study": "time",
        "scheme": scheme,
        "module": SCHEME_MODULES[scheme][0],
        "options": SCHEME_MODULES[scheme][1],
        "level": study["level"],
        "taus": study["taus"],
        "reference_factor": study["reference_factor"],
        "t_final": study["t_final"],
        "radius": 1.0,
        "rtol": float(config["rtol"]),
        "code": {top: code_digest(top) for top in _packages(scheme)},
    }


# {record path: settings} of every input of the beyond aggregation
BEYOND_LEVEL_RUNS = {
    run_record(s, lv): run_settings(s, lv) for s in BEYOND["schemes"] for lv in BEYOND["levels"]
}
BEYOND_LONG_RUNS = {
    beyond_record("long_time", s, BEYOND["long_time"]["level"]): beyond_run_settings(
        "long_time", s, BEYOND["long_time"]["level"]
    )
    for s in BEYOND["long_time"]["schemes"]
}
BEYOND_SPACE_RUNS = {
    beyond_record("space", s, lv): beyond_run_settings("space", s, lv)
    for s in BEYOND["space_study"]["schemes"]
    for lv in BEYOND["space_study"]["levels"]
}
BEYOND_TIME_RUNS = {time_record(s): time_settings(s) for s in BEYOND["time_study"]["schemes"]}


def beyond_seconds(level, steps):
    """Rough single-core wall time of a DDFV run of `steps` steps on `level`, with
    margin (measured alone: 10-13 ms a step on level 5, x4 per level, plus about
    0.6 ms a step of fixed cost; up to 1.5x that with other jobs running)."""
    return steps * (0.02 * 4.0 ** (int(level) - 5) + 0.001)


def beyond_run_runtime(wildcards):
    """Slurm time limit in minutes: 4x the estimate, at least 5."""
    settings = beyond_run_settings(wildcards.study, wildcards.scheme, wildcards.level)
    steps = round(settings["t_final"] / settings["tau"])
    return max(5, math.ceil(4 * beyond_seconds(wildcards.level, steps) / 60))


def time_runtime(wildcards):
    """Slurm time limit of a time study (all its runs and the reference), minutes."""
    study = BEYOND["time_study"]
    steps = sum(round(study["t_final"] / tau) for tau in study["taus"])
    steps += round(study["t_final"] * study["reference_factor"] / study["taus"][-1])
    return max(5, math.ceil(4 * beyond_seconds(study["level"], steps) / 60))


TABLES = [
    "results/tables/convergence.csv",
    "results/tables/convergence.md",
    "results/tables/convergence.tex",
    "results/tables/convergence.csv.json",
]
CONVERGENCE_FIGURES = [
    "results/figures/convergence.png",
    "results/figures/convergence.pdf",
]
CONVERGENCE_TARGETS = TABLES + CONVERGENCE_FIGURES


# every scheme of scheme_modules has run records on request (the beyond study
# runs schemes that `schemes` does not list); longest names first
wildcard_constraints:
    scheme="|".join(re.escape(s) for s in sorted(SCHEME_MODULES, key=len, reverse=True)),
    level=r"[1-9][0-9]*",
