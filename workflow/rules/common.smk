# Target lists and input functions shared by the rules. The logic behind them
# is in the studies' plan modules (mcfbench.studies.<study>.plan), on the plans of
# mcfbench.pipeline.Plans: each study's config section is checked (its plan
# made) while Snakemake reads the workflow, for the run store's batches
# (workflow/rules/runs.smk); a bad value stops only the targets that use it, with a
# message naming the key (no traceback: mcfbench.pipeline.WorkflowPlans).

from mcfbench.pipeline import RunStore, WorkflowPlans
import mcfbench.studies.convergence as _convergence_paths
from mcfbench.studies.beyond import plan as _beyond
from mcfbench.studies.convergence import plan as _convergence
from mcfbench.studies.gallery import plan as _gallery_plan
from mcfbench.storage.run_store import manifest_path as _manifest_path

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


# The specs of the studies' views (RUNS: the run store's plan, workflow/rules/runs.smk;
# called when a view joins the job graph)


def convergence_specs():
    """The specs of Table 3.1 (its plan checked: a bad value is named here)."""
    return list(_convergence.table_specs(PLANS.plan("convergence")).values())


def beyond_specs(studies):
    """The specs of the beyond study's ``studies`` (its plan checked: a bad value is
    named here)."""
    runs = _beyond.study_specs(PLANS)
    return list(dict.fromkeys(s for study in studies for s in runs[study].values()))


def gallery_runs(wildcards):
    """The manifests of the gallery's batches, one per mesh file (gallery.smk)."""
    return [
        _manifest_path(f"gallery_batch{k}")
        for k in range(1, len(GALLERY["meshes"]) + 1)
    ]


def gallery_batch_runs(mesh):
    """The params of the gallery's batch of ``mesh``: its specs (every scheme on the
    file, its SHA-256 taken when the batch joins the job graph) and code digests."""
    return lambda wildcards: RUNS.entries(
        _gallery_plan.mesh_specs(GALLERY, mesh).values()
    )
