# Beyond Table 3.1: level 6, the scheme variants and the T-vertex stability
# study (issue #5). Not part of `rule all`:
#
#   snakemake --cores 2 beyond      # about 8 minutes on 2 cores before the scaling
#   # study ran every scheme; its runs alone 7.4 minutes (config/config.yaml)
#   # and level 7 of the chord variant in the L2/EOC table (config key beyond.finest):
#   snakemake --cores 2 beyond --config 'beyond={finest: {schemes: [ddfv-chord]}}'
#
# Settings: the config key `beyond` (config/README.md), checked by
# mcfbench.studies.beyond.plan when a rule of this file joins the job graph
# (a bad value stops `snakemake beyond`, not the other targets). Five studies, all under results/beyond/
# (results/README.md), for any scheme of the registry mcfbench.running.schemes.SCHEMES:
#
# - levels: every scheme on every level with tau ~ h^2 as in Table 3.1, and
#   the schemes of beyond.finest on one level more (the same specs as Table 3.1's,
#   so the same runs in the run store);
# - long_time: one level continued past t_final (onset of the breakdown);
# - space: refined meshes with one tiny time step (order 2 in space);
# - time: one mesh, tau halved repeatedly (order 1 in time): one run per tau and the
#   reference run, the errors from their saved final states;
# - scaling: CPU seconds per step and peak memory against the unknowns, slopes
#   fitted on beyond.scaling.fit_levels, of every scheme of the registry (unless
#   beyond.scaling.schemes narrows it) on beyond.scaling.levels (a run the levels
#   study also makes is one run of the store); its own rule
#   beyond_scaling, so that its table needs those runs only:
#     snakemake --cores 2 results/beyond/tables/scaling.md
#
# Runs that break down are records like any other (status, t_failed, the T
# monitor of every time level reached); the tables show them as such.
# Specs: mcfbench.studies.beyond.plan through mcfbench.pipeline.Plans (PLANS of
# workflow/rules/common.smk); their batch jobs: workflow/rules/runs.smk.

import mcfbench.studies.beyond as _beyond_paths

BEYOND_TABLES = {
    f"{name}_{ext}": f"{_beyond_paths.TABLES}/{name}.{ext}"
    for name in _beyond_paths.TABLE_NAMES
    for ext in ("csv", "md", "tex")
}
BEYOND_FIGURES = {
    f"{name}_{ext}": f"{_beyond_paths.FIGURES}/{name}.{ext}"
    for name in _beyond_paths.FIGURE_NAMES
    for ext in ("png", "pdf")
}
SCALING_OUTPUTS = {
    **{
        f"scaling_{ext}": f"{_beyond_paths.SCALING}.{ext}"
        for ext in ("csv", "md", "tex")
    },
    "points": f"{_beyond_paths.SCALING}_points.csv",
    "provenance": f"{_beyond_paths.SCALING}.json",
    **{
        f"figure_{ext}": f"{_beyond_paths.SCALING_FIGURE}.{ext}"
        for ext in ("png", "pdf")
    },
}
BEYOND_TARGETS = [
    *BEYOND_TABLES.values(),
    *SCALING_OUTPUTS.values(),
    f"{_beyond_paths.TABLES}/t_monitor.csv",
    f"{_beyond_paths.TABLES}/beyond.json",
    *BEYOND_FIGURES.values(),
    _beyond_paths.FINDINGS,
]


rule beyond_records:
    """Check every run record of the beyond study (a bad one stops here: the tables stay)."""
    input:
        lambda wildcards: RUNS.manifests(beyond_specs(_beyond.TABLE_STUDIES)),
    output:
        f"{_beyond_paths.TABLES}/records.json",
    log:
        "results/logs/beyond/records.log",
    benchmark:
        "results/benchmarks/beyond/records.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        expected=lambda wildcards: RUNS.expected(beyond_specs(_beyond.TABLE_STUDIES)),
    script:
        "../scripts/check_records.py"


rule beyond_tables:
    """The tables of the beyond study (but the scaling study's) and the T monitor series."""
    input:
        checked=f"{_beyond_paths.TABLES}/records.json",
        runs=lambda wildcards: RUNS.manifests(beyond_specs(_beyond.TABLE_STUDIES)),
    output:
        **{
            key: (
                report(
                    path,
                    caption=f"../report/beyond_{key[:-4]}.rst",
                    category="Beyond Table 3.1",
                    labels={"table": key[:-4]},
                )
                if key.endswith("_csv")
                else path
            )
            for key, path in BEYOND_TABLES.items()
        },
        t_monitor=f"{_beyond_paths.TABLES}/t_monitor.csv",
        provenance=f"{_beyond_paths.TABLES}/beyond.json",
    log:
        "results/logs/beyond/tables.log",
    benchmark:
        "results/benchmarks/beyond/tables.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        beyond=lambda wildcards: PLANS.plan("beyond"),
        table=lambda wildcards: PLANS.plan("convergence"),
        paper_schemes=lambda wildcards: _beyond.paper_schemes(PLANS.plan("beyond")),
        settings={k: config[k] for k in ("tau_level_1", "t_final", "rtol")},
    script:
        "../scripts/beyond_tables.py"


rule beyond_figures:
    """L2 per level, the T monitor against time, time and space convergence."""
    input:
        levels=BEYOND_TABLES["levels_csv"],
        stability=BEYOND_TABLES["stability_csv"],
        time=BEYOND_TABLES["time_convergence_csv"],
        space=BEYOND_TABLES["space_convergence_csv"],
        t_monitor=f"{_beyond_paths.TABLES}/t_monitor.csv",
    output:
        **{
            key: (
                report(
                    path,
                    caption=f"../report/beyond_figure_{key[:-4]}.rst",
                    category="Beyond Table 3.1",
                    labels={"figure": key[:-4]},
                )
                if key.endswith("_png")
                else path
            )
            for key, path in BEYOND_FIGURES.items()
        },
    log:
        "results/logs/beyond/figures.log",
    benchmark:
        "results/benchmarks/beyond/figures.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        beyond=lambda wildcards: PLANS.plan("beyond"),
        t_final=config["t_final"],
    script:
        "../scripts/beyond_plots.py"


rule beyond_findings:
    """The written findings, generated from the tables (no hand-typed numbers)."""
    input:
        levels=BEYOND_TABLES["levels_csv"],
        stability=BEYOND_TABLES["stability_csv"],
        time=BEYOND_TABLES["time_convergence_csv"],
        space=BEYOND_TABLES["space_convergence_csv"],
        integrators=BEYOND_TABLES["integrators_csv"],
    output:
        report(
            _beyond_paths.FINDINGS,
            caption="../report/beyond_findings.rst",
            category="Beyond Table 3.1",
            labels={"table": "findings"},
        ),
    log:
        "results/logs/beyond/findings.log",
    benchmark:
        "results/benchmarks/beyond/findings.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=500,
        runtime=5,
    params:
        beyond=lambda wildcards: PLANS.plan("beyond"),
        paper_schemes=lambda wildcards: _beyond.paper_schemes(PLANS.plan("beyond")),
        t_final=config["t_final"],
        tau_level_1=config["tau_level_1"],
    script:
        "../scripts/beyond_findings.py"


rule beyond_scaling:
    """Cost against size: the scaling table, its points and figure from its own runs."""
    input:
        lambda wildcards: RUNS.manifests(beyond_specs(["scaling"])),
    output:
        **{
            key: (
                report(
                    path,
                    caption=(
                        "../report/beyond_scaling.rst"
                        if key == "scaling_csv"
                        else "../report/beyond_figure_scaling.rst"
                    ),
                    category="Beyond Table 3.1",
                    labels=(
                        {"table": "scaling"}
                        if key == "scaling_csv"
                        else {"figure": "scaling"}
                    ),
                )
                if key in ("scaling_csv", "figure_png")
                else path
            )
            for key, path in SCALING_OUTPUTS.items()
        },
    log:
        "results/logs/beyond/scaling.log",
    benchmark:
        "results/benchmarks/beyond/scaling.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        beyond=lambda wildcards: PLANS.plan("beyond"),
        table=lambda wildcards: PLANS.plan("convergence"),
        settings={"t_final": config["t_final"]},
    script:
        "../scripts/beyond_scaling.py"


rule beyond:
    """Target: level 6, the scheme variants and the stability study (slow)."""
    input:
        # the plan first: a bad value under `beyond` is named here
        lambda wildcards: PLANS.checked("beyond", BEYOND_TARGETS),
    localrule: True
