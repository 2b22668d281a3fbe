# Target lists and input functions shared by the rules. The logic behind them
# is in the studies' plan modules (mcfbench.studies.<study>.plan), on the plans of
# mcfbench.pipeline.Plans: each study's config section is checked (its plan
# made) while Snakemake reads the workflow, for the run store's batches
# (workflow/rules/runs.smk); a bad value stops only the targets that use it, with a
# message naming the key (no traceback: mcfbench.pipeline.WorkflowPlans).

from mcfbench.pipeline import RunStore, WorkflowPlans
import mcfbench.studies.convergence as _convergence_paths

PLANS = WorkflowPlans(config, f"{workflow.basedir}/workflow/schemas")
# the config key `threads` (every run job), checked here
THREADS = PLANS.threads
# every compiled kernel in numba's cache before the run jobs (rule compile_kernels),
# one file per version of the code
KERNELS = PLANS.kernels


TABLES = [
    f"{_convergence_paths.TABLE}.{ext}" for ext in ("csv", "md", "tex", "csv.json")
]
CONVERGENCE_FIGURES = [f"{_convergence_paths.FIGURE}.{ext}" for ext in ("png", "pdf")]
CONVERGENCE_TARGETS = TABLES + CONVERGENCE_FIGURES
