# Convergence study of Section 3.1 (Table 3.1): the DDFV scheme and the
# cotangent baseline on the shrinking sphere.
#
#   snakemake --cores 2                          # everything under results/
#   snakemake --cores 2 --config levels=[1,2,3]  # fewer levels
#   snakemake --report results/report.html       # HTML report afterwards
#
# Settings: config/config.yaml (documented in config/README.md), validated
# against workflow/schemas/config.schema.yaml, then each study's section
# across keys (scheme names against the registry mcfbench.running.schemes.SCHEMES,
# time steps; the plan of its module in mcfbench/studies/) when a target
# needs it, before any job runs. The logic of the rules is in the harness (mcfbench);
# workflow/scripts/*.py are thin adapters. Needs the packages installed:
# `pip install -e .` in the repository.

import os

from snakemake.utils import min_version

from mcfbench.pipeline import (
    check_config,
    jobs_environment,
    message_only,
    study_rule_files,
)
from mcfbench.storage.provenance import BLAS_THREAD_VARIABLES

# One BLAS thread per job, set once here: every job inherits it (local or
# Slurm), before any of them imports numpy. The jobs' run records store these
# variables (mcfbench.storage.provenance.BLAS_THREAD_VARIABLES).
os.environ.update(dict.fromkeys(BLAS_THREAD_VARIABLES, "1"))
# The jobs import the packages this workflow planned their runs with (the code
# digests of the batches' params), not another copy (mcfbench.pipeline.jobs_pythonpath).
os.environ.update(jobs_environment())

min_version("9.0")


configfile: "config/config.yaml"


# a bad value ends Snakemake with one message naming the key, no traceback
with message_only():
    check_config(config, "workflow/schemas/config.schema.yaml")


report: "workflow/report/workflow.rst"


include: "workflow/rules/common.smk"
include: "workflow/rules/kernels.smk"
include: "workflow/rules/runs.smk"


# every study's rule file, in name order (report.smk after beyond.smk and
# figures.smk, whose targets it reads): a new study is a rule file there, no line here
for _rules in study_rule_files(f"{workflow.basedir}/workflow/rules"):

    include: _rules


rule all:
    default_target: True
    input:
        CONVERGENCE_TARGETS,
        FIGURE_TARGETS,
        REPORT_TARGETS,
    localrule: True
