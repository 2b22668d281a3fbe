# The benchmark matrix: every scheme x every problem x its refinement series
# (issue "The benchmark matrix"). Not part of `rule all`:
#
#   snakemake --cores 2 matrix      # the default matrix
#
# Settings: the config key `matrix` (config/config.yaml), checked against the
# registries mcfbench.running.schemes.SCHEMES and mcfbench.running.problems.PROBLEMS by
# mcfbench.studies.matrix.plan (after workflow/schemas/matrix.schema.yaml)
# before any job runs. Everything but the rules is in the study's folder
# mcfbench/studies/matrix/ (plan, job, aggregate, tables, findings, plots, page),
# the output paths too (mcfbench/studies/matrix/__init__.py).
#
# Its runs are specs in the run store (results/runs/, workflow/rules/runs.smk: one
# record and the first and last frames per run). Outputs under results/matrix/:
#   tables/matrix.csv                            the long table (one row per metric)
#   tables/{problem}.md, .tex                    one table per problem, schemes as rows
#   tables/summary.md, .tex, .csv                problem x scheme
#   figures/errors, quality, pictures (.png, .pdf)
#   findings.md                                  written from the numbers only
#   index.html                                   the results page: sortable tables, figures,
#                                                findings, in one offline file

import mcfbench.studies.matrix as _matrix_paths
from mcfbench.studies.matrix import plan as _matrix
from mcfbench.pipeline import alternatives as _alternatives

# the plan; without problems (no runs) when the section `matrix` is bad: then
# `snakemake matrix` names the bad key (rule matrix), the other targets run
MATRIX = PLANS.while_reading("matrix", {"schemes": [], "problems": {}})
# the manifests of the batches of its runs (workflow/rules/runs.smk): a run is
# redone when its spec or the code that computes it changes, not the tables or plots
MATRIX_RUNS = RUNS.manifests(_matrix.planned_specs(MATRIX).values())


MATRIX_TABLES = _matrix_paths.table_files(MATRIX["problems"])
MATRIX_FIGURES = _matrix_paths.figure_files()
MATRIX_TARGETS = [
    *MATRIX_TABLES,
    *MATRIX_FIGURES.values(),
    _matrix_paths.FINDINGS,
    _matrix_paths.PAGE,
]


rule matrix_tables:
    """The long table, one table per problem and the summary."""
    input:
        MATRIX_RUNS,
    output:
        MATRIX_TABLES,
    log:
        "results/logs/matrix/tables.log",
    benchmark:
        "results/benchmarks/matrix/tables.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1500,
        runtime=10,
    # the plan, not the spec of every run (which the script makes from it): a
    # changed matrix is named in a few lines, not hundreds
    params:
        plan=MATRIX,
    script:
        "../scripts/matrix_tables.py"


rule matrix_plots:
    """Error and cost against h (from the long table), mesh quality over time (from
    the records)."""
    input:
        table=_matrix_paths.LONG_TABLE,
        runs=MATRIX_RUNS,
    output:
        **{k: v for k, v in MATRIX_FIGURES.items() if not k.startswith("pictures")},
    log:
        "results/logs/matrix/plots.log",
    benchmark:
        "results/benchmarks/matrix/plots.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        plan=MATRIX,
    script:
        "../scripts/matrix_plots.py"


# The picture grid apart: the longest of the figures (the last full matrix's
# results, 2026-11-26: errors 11 s, work-precision 12 s, quality 10 s CPU, the grid
# the rest of the 119 s of the one job that made all four). It needs neither the
# tables nor the finer levels: it runs beside the tables, the other figures and
# the findings.
rule matrix_pictures:
    """The final surfaces, scheme x problem, at the coarsest level."""
    input:
        RUNS.manifests(_matrix.picture_specs(MATRIX).values()),
    output:
        png=MATRIX_FIGURES["pictures_png"],
        pdf=MATRIX_FIGURES["pictures_pdf"],
    log:
        "results/logs/matrix/pictures.log",
    benchmark:
        "results/benchmarks/matrix/pictures.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        plan=MATRIX,
    script:
        "../scripts/matrix_pictures.py"


rule matrix_findings:
    """findings.md from the summary table (no hand-typed numbers)."""
    input:
        summary=_matrix_paths.SUMMARY,
        table=_matrix_paths.LONG_TABLE,
    output:
        _matrix_paths.FINDINGS,
    log:
        "results/logs/matrix/findings.log",
    benchmark:
        "results/benchmarks/matrix/findings.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        plan=MATRIX,
    script:
        "../scripts/matrix_findings.py"


rule matrix_page:
    """The results page: the tables (sortable), the figures and the findings in one
    self-contained HTML file."""
    input:
        table=_matrix_paths.LONG_TABLE,
        summary=_matrix_paths.SUMMARY,
        figures=[MATRIX_FIGURES[f"{name}_png"] for name in _matrix_paths.FIGURE_NAMES],
        findings=_matrix_paths.FINDINGS,
    output:
        _matrix_paths.PAGE,
    log:
        "results/logs/matrix/page.log",
    benchmark:
        "results/benchmarks/matrix/page.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        plan=MATRIX,
    script:
        "../scripts/matrix_page.py"


rule matrix:
    """Target: every scheme x every problem x its levels (config key `matrix`),
    tables, figures and findings in results/matrix/."""
    input:
        # the plan first: a bad value under `matrix` is named here
        lambda wildcards: PLANS.checked("matrix", MATRIX_TARGETS),
    localrule: True
