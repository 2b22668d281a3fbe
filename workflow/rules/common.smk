# Target lists and input functions shared by the rules. The logic behind them
# is in the study modules (mcfbench.studies.convergence, .beyond), reached
# through mcfbench.pipeline.Plans: each study's config section is checked
# (its plan made) when a rule that needs it joins the job graph, so a bad
# value stops only the targets that use it, with a message naming the key
# (no traceback: mcfbench.pipeline.WorkflowPlans).

from mcfbench.pipeline import WorkflowPlans, mem_mb, scheme_pattern

PLANS = WorkflowPlans(config, f"{workflow.basedir}/workflow/schemas")
# the config key `threads` (every run job), checked here
THREADS = PLANS.threads
# every compiled kernel in numba's cache before the run jobs (rule compile_kernels),
# one file per version of the code
KERNELS = PLANS.kernels


def run_settings(wildcards):
    return PLANS.run_settings(wildcards.scheme, wildcards.level)


def run_runtime(wildcards):
    return PLANS.run_runtime(wildcards.level)


def run_mem_mb(wildcards):
    return mem_mb(wildcards.level)


def beyond_run_settings(wildcards):
    return PLANS.beyond_run_settings(wildcards.study, wildcards.scheme, wildcards.level)


def beyond_run_runtime(wildcards):
    return PLANS.beyond_runtime(wildcards.study, wildcards.scheme, wildcards.level)


def time_settings(wildcards):
    return PLANS.time_settings(wildcards.scheme)


def time_runtime(wildcards):
    return PLANS.time_runtime()


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


# every scheme of the registry, also as NAME@INTEGRATOR, has run records on
# request (the beyond study runs schemes that `schemes` does not list)
wildcard_constraints:
    scheme=scheme_pattern(),
    level=r"[1-9][0-9]*",
