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
# Outputs under results/matrix/:
#   runs/{problem}/{scheme}/level{level}.json    one record per run (mcfbench.storage.records)
#   frames/{problem}/{scheme}/level{level}.npz   its first and last frame
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

# the plan; without problems (no rules) when the section `matrix` is bad: then
# `snakemake matrix` names the bad key (rule matrix), the other targets run
MATRIX = PLANS.while_reading("matrix", {"schemes": [], "problems": {}})
# a run is redone when the code that computes it changes (not the tables or plots)
MATRIX_CODE = PLANS.code
# {record path: settings} of every run
MATRIX_RUNS = _matrix.planned_runs(MATRIX, MATRIX_CODE)


MATRIX_TABLES = _matrix_paths.table_files(MATRIX["problems"])
MATRIX_FIGURES = _matrix_paths.figure_files()
MATRIX_TARGETS = [
    *MATRIX_TABLES,
    *MATRIX_FIGURES.values(),
    _matrix_paths.FINDINGS,
    _matrix_paths.PAGE,
]


# One job per batch (mcfbench.studies.matrix.plan.batches): the cheap series of a
# problem gathered in one process until their estimated cost reaches about
# 60 CPU s (plan.BATCH_SECONDS), a heavy series alone
# (mcfbench.studies.matrix.job.batch_job); one rule per batch since the outputs
# differ. Saves the start-up of a process and Snakemake's work per job of every
# series but one per batch (about 1.7 s each);
# a killed job redoes its own series. (Snakemake's `group:` would not do it: in
# local execution group definitions are ignored, docs "Job Grouping".)
for _batch in _matrix.batches(MATRIX):
    _levels = MATRIX["problems"][_batch.problem]

    rule:
        name:
            f"matrix_run_{_batch.name}"
        input:
            kernels=ancient(KERNELS),
        output:
            records=[
                _matrix.record_path(_batch.problem, s, k)
                for s in _batch.schemes
                for k in _levels
            ],
            frames=[
                _matrix.frames_path(_batch.problem, s, k)
                for s in _batch.schemes
                for k in _levels
            ],
        log:
            [f"results/logs/matrix/{_batch.problem}/{s}.log" for s in _batch.schemes],
        benchmark:
            f"results/benchmarks/matrix/{_batch.problem}/batch{_batch.index}.tsv"
        # the costliest batches first (estimated CPU s): long jobs start early and
        # the two cores stay busy
        priority: round(_batch.seconds)
        conda:
            "../envs/ddfv.yaml"
        threads: 1
        # one heavy series at most per batch, the others' estimate under 60 s:
        # the bounds of a series job hold for a batch
        resources:
            mem_mb=1500,
            runtime=120,
        # the settings of the problem's runs, not of the batch's series (each
        # run's scheme and level are its record path's): regrouping the batches
        # (other schemes or levels) or trimming levels reruns no run already computed
        params:
            settings=_matrix.problem_settings(MATRIX, _batch.problem, MATRIX_CODE),
        script:
            "../scripts/matrix_run.py"


rule matrix_tables:
    """The long table, one table per problem and the summary."""
    input:
        list(MATRIX_RUNS),
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
    # the plan and the code digest, not the settings of every run (which the script
    # makes from them): a changed matrix is named in a few lines, not hundreds
    params:
        plan=MATRIX,
        code=MATRIX_CODE,
    script:
        "../scripts/matrix_tables.py"


rule matrix_plots:
    """Error and cost against h (from the long table), mesh quality over time (from
    the records)."""
    input:
        table=_matrix_paths.LONG_TABLE,
        records=list(MATRIX_RUNS),
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
        code=MATRIX_CODE,
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
        records=[r for r, _ in _matrix.picture_runs(MATRIX).values()],
        frames=[f for _, f in _matrix.picture_runs(MATRIX).values()],
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
