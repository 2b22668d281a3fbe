# Convergence study of Section 3.1 (Table 3.1): the DDFV scheme and the
# cotangent baseline on the shrinking sphere.
#
#   snakemake --cores 2                          # everything under results/
#   snakemake --cores 2 --config levels=[1,2,3]  # fewer levels
#   snakemake --report results/report.html       # HTML report afterwards
#
# Settings: config/config.yaml (documented in config/README.md), validated
# against workflow/schemas/config.schema.yaml before any job runs.

from snakemake.utils import min_version, validate

min_version("9.0")


configfile: "config/config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/convergence.smk"
# Hook for the figure rules maintained separately: figures.smk defines
# FIGURE_TARGETS (the files `rule all` builds) and its rules.
include: "workflow/rules/figures.smk"
include: "workflow/rules/beyond.smk"
include: "workflow/rules/report.smk"


rule all:
    default_target: True
    localrule: True
    input:
        CONVERGENCE_TARGETS,
        FIGURE_TARGETS,
        REPORT_TARGETS,


rule beyond:
    """Target: level 6, the scheme variants and the stability study (slow)."""
    localrule: True
    input:
        BEYOND_TARGETS,
