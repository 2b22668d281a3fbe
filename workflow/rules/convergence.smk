# Convergence study: one job per (scheme, level), then Table 3.1 and the
# convergence figure from the run records.
#
#   snakemake --cores 2 convergence    # only this study (rule all adds the figures)


rule convergence:
    """Target: Table 3.1 (CSV, Markdown, LaTeX, provenance) and the convergence figure."""
    input:
        # the plan first: a bad value of Table 3.1's keys is named here
        lambda wildcards: PLANS.checked("convergence", CONVERGENCE_TARGETS),
    localrule: True


rule run_scheme:
    """One scheme on one sphere level: results/runs/{scheme}/level{level}.json."""
    input:
        kernels=ancient(KERNELS),
    output:
        _convergence_paths.RUN,
    log:
        "results/logs/runs/{scheme}/level{level}.log",
    benchmark:
        "results/benchmarks/runs/{scheme}/level{level}.tsv"
    # the long runs first, so that the short ones fill the other cores
    priority: lambda wildcards: int(wildcards.level)
    conda:
        "../envs/ddfv.yaml"
    threads: THREADS
    resources:
        mem_mb=run_mem_mb,
        runtime=run_runtime,
    params:
        # includes the source hash of ddfv, baselines, mcfbench: changed code reruns it
        settings=run_settings,
    script:
        "../scripts/run_scheme.py"


rule convergence_records:
    """Check every run record of Table 3.1 (a bad one stops here: the tables stay)."""
    input:
        lambda wildcards: list(_convergence.table_records(PLANS)),
    output:
        f"{_convergence_paths.TABLE}.records.json",
    log:
        "results/logs/convergence_records.log",
    benchmark:
        "results/benchmarks/convergence_records.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        expected=lambda wildcards: _convergence.table_records(PLANS),
    script:
        "../scripts/check_records.py"


rule convergence_table:
    """Table 3.1 with the paper's values and the baselines side by side."""
    input:
        checked=f"{_convergence_paths.TABLE}.records.json",
        records=lambda wildcards: list(_convergence.table_records(PLANS)),
    output:
        csv=report(
            f"{_convergence_paths.TABLE}.csv",
            caption="../report/convergence_table.rst",
            category="Convergence",
            labels={"table": "Table 3.1 (CSV)"},
        ),
        md=f"{_convergence_paths.TABLE}.md",
        tex=f"{_convergence_paths.TABLE}.tex",
        provenance=f"{_convergence_paths.TABLE}.csv.json",
    log:
        "results/logs/convergence_table.log",
    benchmark:
        "results/benchmarks/convergence_table.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        expected=lambda wildcards: _convergence.table_records(PLANS),
        schemes=lambda wildcards: PLANS.plan("convergence")["schemes"],
        levels=lambda wildcards: PLANS.plan("convergence")["levels"],
        settings=lambda wildcards: _convergence.table_settings(
            PLANS.plan("convergence")
        ),
    script:
        "../scripts/convergence_table.py"


rule convergence_figure:
    """Log-log L2 error against h for every scheme and the paper's points."""
    input:
        csv=f"{_convergence_paths.TABLE}.csv",
    output:
        png=report(
            f"{_convergence_paths.FIGURE}.png",
            caption="../report/convergence_figure.rst",
            category="Convergence",
            labels={"figure": "L2 error vs h"},
        ),
        pdf=f"{_convergence_paths.FIGURE}.pdf",
    log:
        "results/logs/convergence_figure.log",
    benchmark:
        "results/benchmarks/convergence_figure.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        t_final=config["t_final"],
    script:
        "../scripts/plot_convergence.py"
