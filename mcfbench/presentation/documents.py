"""The report's documents: Jinja filters and templates, Markdown, self-contained HTML,
LaTeX fragments and the PDF."""

import base64
import functools
import mimetypes
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import jinja2
import markdown

from mcfbench.presentation.formats import (
    MISSING,
    fix,
    int_or,
    num,
    pct,
    pct0,
    sci,
    sig,
    signed,
    tex_escape,
    tex_inline,
    tex_number,
)
from mcfbench.presentation.tables import Table, latex, markdown as markdown_table, md_cell

MARKDOWN_EXTENSIONS = ["tables", "md_in_html", "attr_list", "fenced_code", "sane_lists", "toc"]


def as_list(value):
    if value is None:
        return "not stated"
    if isinstance(value, (list, tuple)):
        return ", ".join(num(v) for v in value) if value else MISSING
    return md_cell(value)


def verdict(ok, text=""):
    """✓ / ✗ / ○ (compared, not checked) as a coloured span, with ``text``."""
    text = f" {text}" if text else ""
    if ok is None:
        return f'<span class="info">○</span>{text}'
    return (f'<span class="pass">✓{text}</span>' if ok
            else f'<span class="fail">✗{text}</span>')


def csv_markdown(table):
    """A CSV file's table of the report (``header``, ``rows`` of text) as Markdown,
    every column left-aligned."""
    return markdown_table(Table(table["header"], table["rows"],
                                align="l" * len(table["header"])))


FILTERS = {"sci": sci, "fix": fix, "sig": sig, "signed": signed, "pct": pct, "pct0": pct0,
           "num": num, "int_or": int_or, "listing": as_list, "verdict": verdict, "cell": md_cell,
           "table": csv_markdown}


@functools.lru_cache(maxsize=4)
def _environment(templates):
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(templates)),
                             undefined=jinja2.StrictUndefined, keep_trailing_newline=True,
                             autoescape=False)
    env.filters.update(FILTERS)
    return env


def environment(templates):
    """The Jinja2 environment of the template folder (compiled templates are
    kept between builds; a changed template file is reloaded)."""
    return _environment(str(Path(templates).resolve()))


def render_markdown(context, templates):
    """The report as Markdown (``reproduction.md.j2``), blank runs squeezed."""
    text = environment(templates).get_template("reproduction.md.j2").render(**context)
    text = re.sub(r"\n{3,}", "\n\n", text)
    return text.strip() + "\n"


_IMG_SRC = re.compile(r'<img\b([^>]*?)\bsrc="([^"]*)"([^>]*)>')


_ANCHOR = re.compile(r'<a\b[^>]*?\bhref="([^"]*)"[^>]*>(.*?)</a>', re.S)


def data_uri(path):
    kind = mimetypes.guess_type(str(path))[0] or "application/octet-stream"
    return f"data:{kind};base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def embed_images(html, base):
    """Every ``<img src>`` relative to ``base`` replaced by a data URI; a
    missing or non-local image becomes a visible note."""
    def embed(match):
        src = match[2]
        if src.startswith("data:"):
            return match[0]
        path = Path(os.path.normpath(Path(base) / src))
        if re.match(r"^[a-z]+:", src) or not path.is_file():
            return f'<span class="fail">✗ image not available: <code>{src}</code></span>'
        return f'<img{match[1]}src="{data_uri(path)}"{match[3]}>'

    return _IMG_SRC.sub(embed, html)


def unlink_files(html):
    """Links other than in-page anchors become their text: the page is
    self-contained, and a relative link would break once it is moved."""
    def keep(match):
        href, text = match[1], match[2]
        return match[0] if href.startswith("#") else f'<span class="link">{text}</span>'

    return _ANCHOR.sub(keep, html)


def external_references(html):
    """Every ``src``/``href`` that is neither a data URI nor an in-page
    anchor (empty for a self-contained page)."""
    refs = re.findall(r'\b(?:src|href|srcset|poster|data)\s*=\s*"([^"]*)"', html)
    refs += re.findall(r"url\(\s*['\"]?([^'\")]+)", html)
    return [r for r in refs if not (r.startswith("data:") or r.startswith("#"))]


def render_html(markdown_text, base, templates, title):
    """The Markdown as one self-contained HTML page (images from ``base``)."""
    md = markdown.Markdown(extensions=MARKDOWN_EXTENSIONS,
                           extension_configs={"toc": {"toc_depth": "2-3"}})
    body = md.convert(markdown_text)
    body = unlink_files(embed_images(body, base))
    # wide tables scroll inside the page instead of widening it
    body = body.replace("<table>", '<div class="table-scroll"><table>').replace(
        "</table>", "</table></div>")
    toc = unlink_files(md.toc)
    # the TOC of the page without its wrapper div and without the title
    css = (Path(templates) / "style.css").read_text()
    env = environment(templates)
    return env.get_template("reproduction.html.j2").render(title=title, css=css, toc=toc,
                                                            body=body)


_LIST_ITEM = re.compile(r"^(\s*)(?:(\d+)[.)]|[-*+])\s+(.*)$")


def markdown_to_tex(text):
    """A subset of Markdown as LaTeX: paragraphs, (nested) lists, headings
    (as \\paragraph), pipe tables, fenced code, inline markup."""
    lines = text.replace("\r\n", "\n").split("\n")
    out, i = [], 0
    while i < len(lines):
        line = lines[i]
        if not line.strip() or re.match(r"^\s*</?(div|figure|figcaption|details|summary)\b",
                                        line):
            i += 1
            continue
        if line.startswith("```"):
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            out.append("\\begin{verbatim}\n" + "\n".join(lines[i + 1:j]) + "\n\\end{verbatim}")
            i = j + 1
            continue
        heading = re.match(r"^#{1,6}\s+(.*)$", line)
        if heading:
            out.append(r"\paragraph{" + tex_inline(heading[1]) + "}")
            i += 1
            continue
        if line.lstrip().startswith("|"):
            j = i
            while j < len(lines) and lines[j].lstrip().startswith("|"):
                j += 1
            out.append(_tex_pipe_table(lines[i:j]))
            i = j
            continue
        if _LIST_ITEM.match(line):
            j = i
            block = []
            while j < len(lines) and (lines[j].strip() == "" or _LIST_ITEM.match(lines[j])
                                      or lines[j].startswith((" ", "\t"))):
                if lines[j].strip() == "" and (j + 1 >= len(lines) or not (
                        _LIST_ITEM.match(lines[j + 1]) or lines[j + 1].startswith((" ", "\t")))):
                    break
                block.append(lines[j])
                j += 1
            out.append(_tex_list(block))
            i = j
            continue
        j = i
        para = []
        while j < len(lines) and lines[j].strip() and not _LIST_ITEM.match(lines[j]) \
                and not lines[j].startswith(("#", "```", "|")):
            para.append(lines[j].strip())
            j += 1
        out.append(tex_inline(" ".join(para)))
        i = j
    return "\n\n".join(out) + "\n"


def _tex_list(block):
    """Items at the smallest indentation; deeper lines continue the item
    (text first, then nested lists or paragraphs, converted recursively)."""
    indent = min(len(_LIST_ITEM.match(b)[1]) for b in block if _LIST_ITEM.match(b))
    items, numbered = [], None
    for line in block:
        m = _LIST_ITEM.match(line)
        if m and len(m[1]) == indent:
            numbered = (m[2] is not None) if numbered is None else numbered
            items.append((m[3], []))
        elif items:
            items[-1][1].append(line)
    body = []
    for head, rest in items:
        rest = _dedent(rest)
        k = next((i for i, x in enumerate(rest) if _LIST_ITEM.match(x) or not x.strip()),
                 len(rest))
        text = " ".join([head] + [x.strip() for x in rest[:k]])
        tail = markdown_to_tex("\n".join(rest[k:])).strip() if k < len(rest) else ""
        body.append(r"\item " + tex_inline(text) + ("\n" + tail if tail else ""))
    env = "enumerate" if numbered else "itemize"
    return f"\\begin{{{env}}}\n" + "\n".join(body) + f"\n\\end{{{env}}}"


def _dedent(lines):
    indent = min((len(x) - len(x.lstrip()) for x in lines if x.strip()), default=0)
    return [x[indent:] for x in lines]


def _cells(line):
    line = line.strip()
    if line.startswith("|"):
        line = line[1:]
    if line.endswith("|") and not line.endswith("\\|"):
        line = line[:-1]
    return [c.strip() for c in re.split(r"(?<!\\)\|", line)]


def _tex_pipe_table(lines):
    header = _cells(lines[0])
    rows = [_cells(x) for x in lines[2:]] if len(lines) > 1 else []
    return latex(Table(header, rows, align="l" * len(header)), head=tex_inline,
                 cell=tex_inline)


def _tex_verdict(ok, text=""):
    mark = r"$\circ$" if ok is None else (r"\checkmark" if ok else r"$\times$")
    return f"{mark} {tex_escape(text)}".strip()


def latex_fragments(context, figure_prefix="figures/"):
    """``{name: text}`` of the LaTeX fragments (see the module docstring).

    Figure files are referenced as ``figures/<name>.pdf`` (and beyond
    images by their path under ``results/``): set ``\\graphicspath`` to the
    ``results/`` folder.
    """
    head = "% generated by mcfbench.studies.report.page from the result files; do not edit\n"
    frags = {}
    env = context["environment"]
    frags["meta"] = head + "\n".join([
        rf"\newcommand{{\reportbuilt}}{{{tex_escape(context['built'])}}}",
        rf"\newcommand{{\reportcommit}}{{\texttt{{{tex_escape(env['git_commit'][:12])}}}}}",
        rf"\newcommand{{\reporthost}}{{\texttt{{{tex_escape(env['host'])}}}}}",
        rf"\newcommand{{\papertitle}}{{{tex_escape(context['paper_settings']['title'])}}}",
    ]) + "\n"
    frags["introduction"] = head + markdown_to_tex(context["text"]["introduction"])
    frags["scheme"] = head + markdown_to_tex(context["text"]["scheme"])

    # Table 3.1 check
    checks = context["checks"]
    header = ["level", "$n_V$", r"$\tau$", "$N$", "$L_2$ paper", "$L_2$ ours", "ours/paper",
              "tolerance", "EOC paper", "EOC ours", "difference",
              f"$\\le {checks['eoc_absolute']}$"]
    rows = []
    for r in context["table"]:
        rows.append([str(r["level"]), int_or(r["ours"]["nV"], r["paper"]["nV"]),
                     num(r["ours"]["tau"] if r["ran"] else r["paper"]["tau"]),
                     int_or(r["ours"]["N"], r["paper"]["N"]),
                     tex_number(sci(r["paper"]["l2_error"], 2)),
                     tex_number(sci(r["ours"]["l2_error"], 4)), fix(r["l2_ratio"], 4)
                     .replace(MISSING, "--"),
                     _tex_verdict(r["l2_ok"], pct0(r["l2_tolerance"])),
                     fix(r["paper"]["eoc"], 2).replace(MISSING, "--"),
                     fix(r["ours"]["eoc"], 3).replace(MISSING, "--"),
                     signed(r["eoc_difference"], 3).replace(MISSING, "--"),
                     _tex_verdict(r["eoc_ok"])])
    cost_header = ["level", "iter paper", "iter ours", "ours/paper", "CPU s paper", "CPU s ours",
                   "ours/paper"]
    cost = [[str(r["level"]), int_or(r["paper"]["iterations"]).replace(MISSING, "--"),
             int_or(r["ours"]["iterations"]).replace(MISSING, "--"),
             fix(r["iter_ratio"], 2).replace(MISSING, "--"),
             fix(r["paper"]["cpu_seconds"], 2).replace(MISSING, "--"),
             sig(r["ours"]["cpu_seconds"], 3).replace(MISSING, "--"),
             sig(r["cpu_ratio"], 3).replace(MISSING, "--")] for r in context["table"]]
    accuracy = Table(header, rows, align="r" * len(header), label="tab:reproduction-accuracy",
                     caption=r"Table~3.1 of the paper against this reproduction (DDFV): $L_2$ "
                     r"error (3.2) with the tolerance it is held to, and EOC (3.1). Checks: "
                     r"\texttt{paper/checks.yaml}.")
    costs = Table(cost_header, cost, align="r" * len(cost_header),
                  label="tab:reproduction-cost", caption="Cost: total BiCGStab iterations and "
                  "CPU seconds, the paper's and ours (compared, not checked).")
    frags["table_3_1"] = head + latex(accuracy, head=str, cell=str) + "\n\n" \
        + latex(costs, head=str, cell=str) + "\n"

    diff = context["differences"]
    parts = [head]
    for title, key, mark in (("Differences", "differs", r"$\neq$"),
                             ("Notes", "notes", r"$\circ$"),
                             ("Agreement", "agrees", r"\checkmark")):
        if diff[key]:
            parts.append(rf"\paragraph{{{title}.}}")
            parts.append("\\begin{itemize}\n" + "\n".join(
                rf"\item[{mark}] " + tex_inline(x) for x in diff[key]) + "\n\\end{itemize}")
    frags["differences"] = "\n".join(parts) + "\n"

    figs = [head]
    for f in context["figures"]:
        if f["png"] is None:
            continue
        label = (f"Fig.~{tex_escape(f['number'])}" if f["paper_figure"]
                 else f"Fig.~{tex_escape(f['number'])}, cotangent side by side")
        paper = (tex_inline(f["paper_caption"]) if f["paper_caption"]
                 else "Not in the paper.")
        checks_text = "; ".join(
            f"{tex_escape(row['what'])}: paper {tex_inline(as_list(row['paper']))}, ours "
            f"{tex_inline(as_list(row['ours']))} {_tex_verdict(row['ok'])}"
            for row in f["rows"])
        figs.append("\n".join([
            r"\begin{figure}[htbp]", r"\centering",
            rf"\includegraphics[width=\linewidth]{{{figure_prefix}{f['name']}.pdf}}",
            rf"\caption{{\textbf{{{label}: {tex_escape(f['title'])}.}} "
            rf"\emph{{Paper:}} {paper} \emph{{Ours:}} {tex_inline(f['caption'])}"
            + (rf" \emph{{Compared:}} {checks_text}." if checks_text else "") + "}",
            rf"\label{{fig:reproduction-{f['name'].replace('_', '-')}}}",
            r"\end{figure}", ""]))
    frags["figures"] = "\n".join(figs)

    beyond = context["beyond"]
    if beyond["present"]:
        parts = [head]
        if beyond["findings"]:
            parts.append(markdown_to_tex(beyond["findings"]["text"]))
        for d in beyond["documents"]:
            parts.append(rf"\subsection*{{{tex_inline(d['title'])}}}")
            # the Markdown the HTML shows, converted (the study's own LaTeX, when it
            # wrote one, is named for manuscripts: its escaping is not checked here)
            if d["tex"]:
                parts.append(f"% the study's own fragment: \\input{{{d['tex']}}}")
            parts.append(markdown_to_tex(d["text"]))
        for t in beyond["tables"]:
            parts.append(rf"\subsection*{{{tex_inline(t['title'])}}}")
            parts.append(latex(Table(t["header"], t["rows"]), head=tex_inline))
        for image in beyond["images"]:
            path = re.sub(r"^results/", "", image["path"])
            parts.append("\n".join([
                r"\begin{figure}[htbp]", r"\centering",
                rf"\includegraphics[width=0.8\linewidth]{{{tex_escape(path)}}}",
                rf"\caption{{{tex_inline(image['caption'])}}}", r"\end{figure}"]))
        frags["beyond"] = "\n\n".join(parts) + "\n"
    else:
        frags["beyond"] = head + tex_inline(
            f"Not run yet: `{beyond['target']}` computes the study beyond Table 3.1 and "
            "rebuilds this report.") + "\n"
    frags["deviations"] = head + markdown_to_tex(context["deviations"])

    prov = context["provenance"]
    rows = [["git commit(s)", ", ".join(rf"\texttt{{{tex_escape(c[:12])}}} ({len(v)})"
                                         for c, v in prov["commits"].items())],
            ["uncommitted changes", f"{len(prov['dirty'])} file(s)"],
            ["host(s)", ", ".join(tex_escape(h) for h in prov["hosts"])],
            ["platform", "; ".join(tex_escape(p) for p in prov["platforms"])],
            ["Python", ", ".join(tex_escape(p) for p in prov["pythons"])],
            ["created (UTC)", f"{tex_escape(prov['created_first'] or '--')} to "
                              f"{tex_escape(prov['created_last'] or '--')}"]]
    rows += [[tex_escape(name), ", ".join(tex_escape(v) for v in versions)]
             for name, versions in prov["packages"].items()]
    frags["provenance"] = head + latex(
        Table(["", "value"], rows, align="ll", label="tab:reproduction-provenance",
              caption="Provenance of the result files (from their JSON records)."),
        head=str, cell=str) + "\n"
    return frags


TEMPLATE = Path("paper/reproduction.tex")


RUNS = 2


def build_pdf(output, template=TEMPLATE, log=None, pdflatex="pdflatex"):
    """Compile ``template`` (paths relative to the working directory, the
    repository root) into ``output``. Raises RuntimeError with pdflatex's
    last lines if a run fails, or if pdflatex is not installed."""
    exe = shutil.which(pdflatex)
    if exe is None:
        raise RuntimeError(f"{pdflatex} not found: the PDF of the report needs a TeX "
                           "installation (e.g. Debian's texlive-latex-recommended); the "
                           "HTML and Markdown reports do not")
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=".pdf-", dir=output.parent) as build:
        command = [exe, "-interaction=nonstopmode", "-halt-on-error", "-file-line-error",
                   f"-output-directory={build}", f"-jobname={output.stem}", str(template)]
        for run in range(RUNS):
            proc = subprocess.run(command, capture_output=True, text=True, timeout=300)
            if log:
                log.info("pdflatex run %d: exit %d", run + 1, proc.returncode)
            if proc.returncode != 0:
                tail = "\n".join(proc.stdout.splitlines()[-30:])
                raise RuntimeError(f"pdflatex failed on {template}:\n{tail}")
        shutil.copyfile(Path(build) / f"{output.stem}.pdf", output)
    if log:
        log.info("wrote %s", output)
    return output
