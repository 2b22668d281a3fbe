# Figures 3.1-3.8 of the paper (and two comparisons with the cotangent
# baseline): one job per figure runs its experiment and draws it. What each
# figure computes (shape, parameters, scheme, tau, steps, panels) is defined
# in one place, mcfbench/studies/figures/experiments.py (EXPERIMENTS); the job
# is mcfbench.studies.figures.job; this file only maps the registry to files.
#
#   snakemake --cores 2 results/figures/fig_3_6.png   # one figure

from mcfbench.studies.figures import figure_outputs
from mcfbench.studies.figures.experiments import EXPERIMENTS

FIGURES = list(EXPERIMENTS)


# every file the job of one figure writes (mcfbench.studies.figures.figure_outputs)
FIGURE_PATHS = {key: str(path) for key, path in figure_outputs("{figure}").items()}
FIGURE_FILES = list(FIGURE_PATHS.values())
FIGURE_TARGETS = expand(FIGURE_FILES, figure=FIGURES)


wildcard_constraints:
    figure="|".join(FIGURES),


rule figure:
    """Run the experiment of one figure (mcfbench/studies/figures/job.py) and draw it.

    Writes the figure, the kept frames (one file per run), per-step mesh-quality diagnostics
    (CSV and plot) and a JSON record with the status of every run. A run
    that breaks down keeps its frames and the job still succeeds; the
    record and a note in the figure say what happened.
    """
    input:
        kernels=ancient(KERNELS),
    output:
        png=report(
            FIGURE_PATHS["png"],
            caption="../report/fig_caption.rst",
            category="Figures 3.1-3.8",
            labels={"figure": "{figure}", "type": "surfaces"},
        ),
        pdf=FIGURE_PATHS["pdf"],
        frames=directory(FIGURE_PATHS["frames"]),
        record=FIGURE_PATHS["record"],
        csv=FIGURE_PATHS["csv"],
        plot=report(
            FIGURE_PATHS["plot"],
            caption="../report/fig_diagnostics.rst",
            category="Figures 3.1-3.8",
            labels={"figure": "{figure}", "type": "mesh quality"},
        ),
    log:
        "results/logs/figures/{figure}.log",
    benchmark:
        "results/benchmarks/figures/{figure}.tsv"
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        title=lambda wildcards: EXPERIMENTS[wildcards.figure].title,
        caption=lambda wildcards: EXPERIMENTS[wildcards.figure].caption,
        settings=lambda wildcards: EXPERIMENTS[wildcards.figure].describe(),
        # rerun when the experiment's definition changes
        config=lambda wildcards: EXPERIMENTS[wildcards.figure].config(),
    script:
        "../scripts/figure.py"
