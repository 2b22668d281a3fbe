# The reproduction report (results/paper/), built from the result files:
# Markdown, one self-contained HTML page, a JSON of every check, and LaTeX
# fragments. Sources: paper/ (published values, captions, checks, text,
# templates) and the section "Deviations and interpretations" of
# ddfv/README.md. Logic: mcfbench/studies/report/page.py (`mcfbench report` by hand).
#
#   snakemake --cores 2                       # builds it (part of rule all)
#   snakemake --cores 2 reproduction_report   # only the report (and what it needs)
#   snakemake --cores 2 beyond                # the beyond study, then the report again
#   snakemake --cores 1 report_pdf            # optional PDF, needs pdflatex
#
# Beyond the paper: the report shows whatever `snakemake beyond` left under
# results/beyond/ (tables, plots, findings.md) when it is built. To rebuild
# it after the beyond study, its files are added to BEYOND_TARGETS (rule
# beyond, Snakefile), and when the target `beyond` is requested the report
# also depends on the beyond outputs: it then waits for them and is redone
# when they change. The default `snakemake` never depends on them, so it
# never (re)computes the slow beyond study; it rebuilds the report only when
# its own inputs change (or once after a `snakemake beyond`, whose input set
# differs), reading the beyond files that are present.

REPORT_DIR = "results/paper"
REPORT_TEX_FRAGMENTS = [
    "meta",
    "introduction",
    "scheme",
    "table_3_1",
    "differences",
    "figures",
    "beyond",
    "deviations",
    "provenance",
]
REPORT_TEX = {
    f"tex_{name}": f"{REPORT_DIR}/tex/{name}.tex" for name in REPORT_TEX_FRAGMENTS
}
REPORT_SOURCES = {
    "published": [
        "paper/published/table_3_1.csv",
        "paper/published/captions.yaml",
        "paper/published/settings.yaml",
    ],
    "checks": "paper/checks.yaml",
    "texts": ["paper/text/introduction.md", "paper/text/scheme.md"],
    "templates": [
        "paper/templates/reproduction.md.j2",
        "paper/templates/reproduction.html.j2",
        "paper/templates/style.css",
    ],
    "readme": "ddfv/README.md",
}
REPORT_TARGETS = [
    f"{REPORT_DIR}/reproduction.md",
    f"{REPORT_DIR}/reproduction.html",
    f"{REPORT_DIR}/reproduction.json",
    *REPORT_TEX.values(),
]

# the beyond study's own outputs (before the report is added to them)
BEYOND_RESULTS = list(BEYOND_TARGETS)
BEYOND_TARGETS = [*BEYOND_RESULTS, *REPORT_TARGETS]


# the result files the report reads; plus, when `beyond` is requested, the
# beyond outputs (see the header)
REPORT_INPUTS = {
    "table": "results/tables/convergence.csv",
    "table_provenance": "results/tables/convergence.csv.json",
    "convergence_figure": "results/figures/convergence.png",
    "figures": expand("results/figures/{figure}.png", figure=FIGURES),
    "figure_records": expand("results/runs/figures/{figure}.json", figure=FIGURES),
    "frames": expand("results/runs/figures/{figure}", figure=FIGURES),
    "diagnostics": expand("results/diagnostics/{figure}.png", figure=FIGURES),
    **REPORT_SOURCES,
}


rule reproduction_report:
    """The paper's results rebuilt from the result files, next to the published ones."""
    input:
        # `workflow.dag_settings.targets`: the targets on the command line
        unpack(
            lambda wildcards: {
                **REPORT_INPUTS,
                "records": RUNS.manifests(convergence_specs()),
                "beyond": (
                    BEYOND_RESULTS
                    if "beyond"
                    in set(getattr(workflow.dag_settings, "targets", None) or ())
                    else []
                ),
            }
        ),
    output:
        **REPORT_TEX,
        md=report(
            f"{REPORT_DIR}/reproduction.md",
            caption="../report/report_markdown.rst",
            category="Reproduction report",
            labels={"file": "Markdown"},
        ),
        html=report(
            f"{REPORT_DIR}/reproduction.html",
            caption="../report/report_html.rst",
            category="Reproduction report",
            labels={"file": "HTML (self-contained)"},
        ),
        json=report(
            f"{REPORT_DIR}/reproduction.json",
            caption="../report/report_checks.rst",
            category="Reproduction report",
            labels={"file": "checks (JSON)"},
        ),
    log:
        "results/logs/report.log",
    benchmark:
        "results/benchmarks/report.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        # results/, paper/ and results/beyond/ are found from the inputs
        beyond_targets=BEYOND_RESULTS,
        figures=FIGURES,
    script:
        "../scripts/report.py"


rule report_pdf:
    """Optional: paper/reproduction.tex with the fragments and PDF figures (needs pdflatex)."""
    input:
        template="paper/reproduction.tex",
        fragments=list(REPORT_TEX.values()),
        tables="results/tables/convergence.tex",
        figures=expand("results/figures/{figure}.pdf", figure=[*FIGURES, "convergence"]),
    output:
        pdf=f"{REPORT_DIR}/reproduction.pdf",
    log:
        "results/logs/report_pdf.log",
    benchmark:
        "results/benchmarks/report_pdf.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    script:
        "../scripts/report_pdf.py"
