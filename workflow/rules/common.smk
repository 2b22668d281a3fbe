# Target lists and input functions shared by the rules. The logic behind them
# is in the studies' plan modules (mcfbench.studies.convergence.plan, .beyond.plan),
# on the plans of mcfbench.pipeline.Plans: each study's config section is checked
# (its plan made) when a rule that needs it joins the job graph, so a bad
# value stops only the targets that use it, with a message naming the key
# (no traceback: mcfbench.pipeline.WorkflowPlans).

from mcfbench.pipeline import WorkflowPlans, mem_mb, runtime_minutes, scheme_pattern
from mcfbench.studies.beyond import plan as _beyond
from mcfbench.studies.convergence import plan as _convergence
import mcfbench.studies.convergence as _convergence_paths

PLANS = WorkflowPlans(config, f"{workflow.basedir}/workflow/schemas")
# the config key `threads` (every run job), checked here
THREADS = PLANS.threads
# every compiled kernel in numba's cache before the run jobs (rule compile_kernels),
# one file per version of the code
KERNELS = PLANS.kernels


def run_settings(wildcards):
    return _convergence.sphere_run_settings(PLANS, wildcards.scheme, wildcards.level)


def run_runtime(wildcards):
    steps = _convergence.level_steps(PLANS.plan("convergence"), wildcards.level)
    return runtime_minutes(wildcards.level, steps)


def run_mem_mb(wildcards):
    return mem_mb(wildcards.level)


def beyond_run_settings(wildcards):
    return _beyond.study_run_settings(
        PLANS, wildcards.study, wildcards.scheme, wildcards.level
    )


def beyond_run_runtime(wildcards):
    settings = beyond_run_settings(wildcards)
    return runtime_minutes(
        wildcards.level, round(settings["t_final"] / settings["tau"])
    )


def time_settings(wildcards):
    return _beyond.time_run_settings(PLANS, wildcards.scheme)


def time_runtime(wildcards):
    plan = PLANS.plan("beyond")
    return runtime_minutes(plan["time_study"]["level"], _beyond.time_steps_total(plan))


TABLES = [
    f"{_convergence_paths.TABLE}.{ext}" for ext in ("csv", "md", "tex", "csv.json")
]
CONVERGENCE_FIGURES = [f"{_convergence_paths.FIGURE}.{ext}" for ext in ("png", "pdf")]
CONVERGENCE_TARGETS = TABLES + CONVERGENCE_FIGURES


# every scheme of the registry, also as NAME@INTEGRATOR, has run records on
# request (the beyond study runs schemes that `schemes` does not list)
wildcard_constraints:
    scheme=scheme_pattern(),
    level=r"[1-9][0-9]*",
