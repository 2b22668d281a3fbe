# Target lists and input functions shared by the rules. The logic behind them
# (checks of the config across keys, the settings of every run record, the
# resources of the jobs) is mcfbench.pipeline.Pipeline: a bad value stops
# Snakemake here, before any job, with a message naming the config key.

from mcfbench.pipeline import Pipeline

PIPELINE = Pipeline(config)
LEVELS = PIPELINE.levels
SCHEMES = PIPELINE.schemes
# the config key `beyond`, checked and normalised
BEYOND = PIPELINE.beyond
THREADS = PIPELINE.threads
# {study: {record path: settings}} of the beyond study (workflow/rules/beyond.smk)
BEYOND_RUNS = PIPELINE.beyond_runs()
# schemes of the beyond study compared with the published Table 3.1 (DDFV family)
BEYOND_PAPER_SCHEMES = PIPELINE.paper_schemes()
# every compiled kernel in numba's cache before the run jobs (rule compile_kernels)
KERNELS = "results/logs/kernels.json"


def run_settings(wildcards):
    return PIPELINE.run_settings(wildcards.scheme, wildcards.level)


def run_runtime(wildcards):
    return PIPELINE.run_runtime(wildcards.level)


def run_mem_mb(wildcards):
    return PIPELINE.mem_mb(wildcards.level)


def beyond_run_settings(wildcards):
    return PIPELINE.beyond_run_settings(
        wildcards.study, wildcards.scheme, wildcards.level
    )


def beyond_run_runtime(wildcards):
    return PIPELINE.beyond_runtime(wildcards.study, wildcards.scheme, wildcards.level)


def time_settings(wildcards):
    return PIPELINE.time_settings(wildcards.scheme)


def time_runtime(wildcards):
    return PIPELINE.time_runtime()


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


# every scheme of the registry has run records on request (the beyond study
# runs schemes that `schemes` does not list)
wildcard_constraints:
    scheme=PIPELINE.scheme_pattern(),
    level=r"[1-9][0-9]*",
