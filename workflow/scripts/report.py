"""Build the reproduction report from the result files.

Called by rule ``reproduction_report`` (workflow/rules/report.smk), or by
hand from the repository root:

    python workflow/scripts/report.py            # results/ -> results/paper/

Writes into the report folder (default ``results/paper/``):

- ``reproduction.md``: the report as Markdown (images linked relatively),
- ``reproduction.html``: the same as one self-contained page (CSS inline,
  images as base64 data URIs; opens offline),
- ``reproduction.json``: every check with its verdict, the provenance
  summary and the SHA-256 of every input,
- ``tex/*.tex``: LaTeX fragments (tables, figures, text) for
  ``paper/reproduction.tex`` or a manuscript.

Sources: ``paper/`` (published values, captions, checks, text, templates)
and ``ddfv/README.md`` (deviations). The data and checks are gathered by
``report_data.py``, formatted by ``report_render.py``.
"""

import argparse
import datetime
import json
import sys
import time
from pathlib import Path

# the repository first on sys.path (ddfv from this checkout), as the other scripts
from run_records import setup_logging, write_text_atomic  # noqa: E402

import report_data  # noqa: E402
import report_render  # noqa: E402

TEX_FRAGMENTS = ("meta", "introduction", "scheme", "table_3_1", "differences", "figures",
                 "beyond", "deviations", "provenance")
TEXTS = ("introduction", "scheme")
PACKAGE_NAMES = ("ddfv-mcf", "numpy", "scipy", "libigl", "pandas", "matplotlib", "snakemake",
                 "jinja2", "markdown", "pyyaml")
TITLE = "Reproduction report: DDFV for mean curvature flow of surfaces"


def default_outputs(out):
    out = Path(out)
    outputs = {"md": out / "reproduction.md", "html": out / "reproduction.html",
               "json": out / "reproduction.json"}
    outputs.update({f"tex_{name}": out / "tex" / f"{name}.tex" for name in TEX_FRAGMENTS})
    return outputs


def _inputs(sources, context):
    """Every file the report read, for the SHA-256 list of the JSON."""
    results, paper = sources.results, sources.paper
    paths = [results / "tables" / "convergence.csv", results / "tables" / "convergence.csv.json",
             results / "figures" / "convergence.png", sources.readme]
    paths += sorted((paper / "published").glob("*")) + [paper / "checks.yaml"]
    paths += sorted((paper / "text").glob("*.md")) + sorted((paper / "templates").glob("*"))
    paths += [results / "runs" / f"{key}.json" for key in context["records"]]
    for f in context["figures"]:
        name = f["name"]
        paths += [results / "figures" / f"{name}.png", results / "diagnostics" / f"{name}.png",
                  results / "runs" / "figures" / f"{name}.json",
                  results / "runs" / "figures" / f"{name}.npz"]
    if sources.beyond is not None and sources.beyond.is_dir():
        paths += sorted(p for p in sources.beyond.rglob("*") if p.is_file())
    root = results.parent
    return {report_data.display_path(p, root): report_data.sha256(p)
            for p in paths if Path(p).is_file()}


def _json_default(value):
    if isinstance(value, Path):
        return value.as_posix()
    if isinstance(value, (set, tuple)):
        return list(value)
    if hasattr(value, "item"):
        return value.item()
    return str(value)


def build(sources, outputs=None, log=None):
    """Collect, check and render; write every output. Returns the context."""
    start = time.perf_counter()
    outputs = {k: Path(v) for k, v in (outputs or default_outputs(sources.out)).items()}
    context = report_data.collect(sources)
    root = sources.results.parent
    html_path = report_data.display_path(outputs["html"], root)
    context.update(
        built=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        snakemake=report_data.SNAKEMAKE,
        text={name: (sources.paper / "text" / f"{name}.md").read_text().strip()
              for name in TEXTS},
        package_names=PACKAGE_NAMES,
        deviation_refs={key: (f"deviation {n} below" if n else "see the deviations below")
                        for key, n in (("iteration", report_data.deviation_number(
                            context["deviations"], "iteration")),)},
        paths={"html": html_path, "json": report_data.display_path(outputs["json"], root),
               "table": report_data.display_path(sources.results / "tables" / "convergence.csv",
                                                 root),
               "table_provenance": report_data.display_path(
                   sources.results / "tables" / "convergence.csv.json", root),
               "tex_table": report_data.display_path(outputs["tex_table_3_1"], root),
               "example_record": next(
                   (f"results/runs/{key}.json" for key in context["records"]),
                   "results/runs/ddfv/level1.json")},
    )
    templates = sources.paper / "templates"
    md = report_render.render_markdown(context, templates)
    html = report_render.render_html(md, outputs["md"].parent, templates, TITLE)
    external = report_render.external_references(html)
    if external:
        raise report_data.ReportError(f"the HTML report would load {external[:5]}: "
                                      "every resource must be embedded")
    fragments = report_render.latex_fragments(context)

    for key, path in outputs.items():
        path.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(outputs["md"], md)
    write_text_atomic(outputs["html"], html)
    for name in TEX_FRAGMENTS:
        write_text_atomic(outputs[f"tex_{name}"], fragments[name])
    summary = {
        "built": context["built"],
        "seconds": round(time.perf_counter() - start, 3),
        "glance": context["glance"], "differences": context["differences"],
        "table_3_1": context["table"], "schemes": context["comparison"],
        "figures": [{k: v for k, v in f.items() if k != "provenance"}
                    for f in context["figures"]],
        "beyond": {k: v for k, v in context["beyond"].items() if k != "provenance"},
        "stale": context["stale"], "settings": context["settings"],
        "checks": context["checks"], "provenance": context["provenance"],
        "environment": context["environment"],
        "inputs": _inputs(sources, context),
        "outputs": {k: report_data.display_path(v, root) for k, v in outputs.items()},
    }
    write_text_atomic(outputs["json"], json.dumps(summary, indent=2, default=_json_default)
                      + "\n")
    if log:
        differs = context["differences"]["differs"]
        log.info("report: %d difference(s) from the paper, %d note(s); %.2f s",
                 len(differs), len(context["differences"]["notes"]),
                 time.perf_counter() - start)
        for item in differs:
            log.info("differs: %s", item)
        log.info("wrote %s", ", ".join(str(p) for p in outputs.values()))
    return context


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--results", type=Path, default=Path("results"))
    parser.add_argument("--paper", type=Path, default=Path("paper"))
    parser.add_argument("--readme", type=Path, default=Path("ddfv/README.md"))
    parser.add_argument("--out", type=Path, default=None,
                        help="report folder (default: RESULTS/paper)")
    parser.add_argument("--beyond", type=Path, default=None,
                        help="beyond-the-paper folder (default: RESULTS/beyond)")
    parser.add_argument("--log", type=Path, default=None)
    args = parser.parse_args(argv)
    sources = report_data.Sources(results=args.results, paper=args.paper, readme=args.readme,
                                  out=args.out or args.results / "paper",
                                  beyond=args.beyond or args.results / "beyond")
    log = setup_logging(args.log or sources.out / "report.log")
    try:
        build(sources, log=log)
    except report_data.ReportError as err:
        log.error("%s", err)
        return 1
    return 0


def _from_snakemake(smk):
    log = setup_logging(smk.log[0])
    results = Path(smk.input.table).parents[1]            # results/tables/convergence.csv
    sources = report_data.Sources(results=results, paper=Path(smk.input.checks).parent,
                                  readme=smk.input.readme, out=Path(smk.output.html).parent,
                                  beyond=results / "beyond",
                                  beyond_targets=tuple(smk.params.beyond_targets),
                                  figures=tuple(smk.params.figures))
    outputs = {key: smk.output[key] for key in default_outputs(".")}
    try:
        build(sources, outputs, log=log)
    except report_data.ReportError as err:
        log.error("%s", err)
        sys.exit(1)


if __name__ == "__main__":
    if "snakemake" in globals():
        _from_snakemake(snakemake)  # noqa: F821
    else:
        sys.exit(main())
