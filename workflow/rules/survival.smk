# The survival study (issue #44, item 4): every scheme on every raw mesh of the corpus
# mcfbench/data/raw_meshes that the intake reads, 40 steps of 0.1 h^2: the share each
# scheme takes to the end, with and without thin features. Not part of `rule all`:
#
#   snakemake --cores 2 survival
#
# Settings: the config key `survival` (mcfbench.studies.survival.plan). Its runs are
# specs of the run store (workflow/rules/runs.smk); outputs under results/survival/:
# runs.csv, survival.md, survival.csv, findings.md.

import mcfbench.studies.survival as _survival
from mcfbench.studies.survival import plan as _survival_plan

# the plan; without meshes (no runs) when the section `survival` is bad: then
# `snakemake survival` names the bad key (rule survival)
SURVIVAL = PLANS.while_reading("survival", {"meshes": {}, "schemes": [], "refused": []})
SURVIVAL_RUNS = _survival_plan.survival_specs(SURVIVAL) if SURVIVAL["meshes"] else {}
SURVIVAL_TARGETS = [
    _survival.RUNS_TABLE,
    f"{_survival.SUMMARY}.md",
    f"{_survival.SUMMARY}.csv",
    _survival.FINDINGS,
]


rule survival_tables:
    """The runs, the share of the meshes each scheme takes to the end, the findings."""
    input:
        RUNS.manifests(SURVIVAL_RUNS.values()),
    output:
        SURVIVAL_TARGETS,
    log:
        "results/logs/survival/tables.log",
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        view="survival.aggregate",
        plan=SURVIVAL,
        runs=list(SURVIVAL_RUNS),
        expected=RUNS.expected(SURVIVAL_RUNS.values()),
    script:
        "../scripts/view.py"


rule survival:
    """Target: every scheme on the raw corpus (config key `survival`), results/survival/."""
    input:
        # the plan first: a bad value under `survival` is named here
        lambda wildcards: PLANS.checked("survival", SURVIVAL_TARGETS),
    localrule: True
