# Every compiled (numba) kernel into numba's cache once, before the run jobs:
# the rules that run schemes take KERNELS (common.smk) as an `ancient` input,
# so a fresh clone's first pipeline run compiles once instead of once per
# job, and a rerun of this rule alone does not rerun them. KERNELS is named by
# the runs' code identities (mcfbench.pipeline.Plans.kernels): a change of a run's
# code compiles again, in the same invocation as the runs it redoes.
rule compile_kernels:
    """Compile every scheme's and the solver's kernels once, before the run jobs."""
    output:
        KERNELS,
    log:
        "results/logs/kernels.log",
    benchmark:
        "results/benchmarks/kernels.tsv"
    conda:
        "../envs/ddfv.yaml"
    threads: THREADS
    resources:
        mem_mb=500,
        runtime=10,
    params:
        threads=THREADS,
    script:
        "../scripts/compile_kernels.py"
