# Every compiled (numba) kernel into numba's cache once, before the run jobs:
# the rules that run schemes take KERNELS (common.smk) as an `ancient` input,
# so a fresh clone's first pipeline run compiles once instead of once per
# job, and a rerun of this rule alone does not rerun them.
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
        # a code change compiles again (the cache is keyed by source file)
        code=PLANS.code,
        threads=THREADS,
    script:
        "../scripts/compile_kernels.py"
