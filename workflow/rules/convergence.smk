# Convergence study: Table 3.1 and the convergence figure from the run store's
# records of its specs (mcfbench.studies.convergence.plan.table_specs; their batch
# jobs: workflow/rules/runs.smk).
#
#   snakemake --cores 2 convergence    # only this study (rule all adds the figures)


rule convergence:
    """Target: Table 3.1 (CSV, Markdown, LaTeX, provenance) and the convergence figure."""
    input:
        # the plan first: a bad value of Table 3.1's keys is named here
        lambda wildcards: PLANS.checked("convergence", CONVERGENCE_TARGETS),
    localrule: True


rule convergence_records:
    """Check every run record of Table 3.1 (a bad one stops here: the tables stay)."""
    input:
        lambda wildcards: RUNS.manifests(convergence_specs()),
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
        expected=lambda wildcards: RUNS.expected(convergence_specs()),
    script:
        "../scripts/check_records.py"


rule convergence_table:
    """Table 3.1 with the paper's values and the baselines side by side."""
    input:
        checked=f"{_convergence_paths.TABLE}.records.json",
        runs=lambda wildcards: RUNS.manifests(convergence_specs()),
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
        expected=lambda wildcards: RUNS.expected(convergence_specs()),
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
