"""Table 3.1 of the paper, as published and as computed by any scheme.

The experiment is the problem ``sphere`` (:mod:`mcfbench.running.problems`): level
``k`` is the icosphere refined ``k`` times with ``tau = 0.04 / 4**(k - 1)``
(``tau ~ h^2``) up to ``t_f = 0.08``, the error (3.2).
"""

import math
import re

import numpy as np
import pandas as pd

from mcfbench.geometry.exact import eoc
from mcfbench.running.schemes import get_scheme
from mcfbench.running.run import level_sweep

# Table 3.1 as published: level -> (n_V, n_F, n_T, tau, N, L2 error, iter, EOC, CPU s)
PUBLISHED = {
    1: (122, 42, 80, 0.04, 2, 1.34e-02, 7, float("nan"), 0.02),
    2: (482, 162, 320, 0.01, 8, 3.26e-03, 34, 2.03, 0.13),
    3: (1922, 642, 1280, 0.0025, 32, 8.01e-04, 128, 2.03, 1.16),
    4: (7682, 2562, 5120, 0.000625, 128, 1.95e-04, 450, 2.04, 12.91),
    5: (30722, 10242, 20480, 0.00015625, 512, 4.66e-05, 1703, 2.07, 194.78),
}
PUBLISHED_COLUMNS = ("nV", "nF", "nT", "tau", "N", "l2_error", "iterations",
                     "eoc", "cpu_seconds")


def sphere_table(levels, scheme="ddfv", **options):
    """Table 3.1: the problem ``sphere`` on each level, EOC and published values.

    Parameters
    ----------
    levels : sequence of int
    scheme : str
        A name of :data:`mcfbench.running.schemes.SCHEMES`.
    **options
        Passed to :func:`mcfbench.running.run.run` (``solver``, scheme options).

    Returns
    -------
    pandas.DataFrame
        One row per level: the fields of :class:`mcfbench.storage.records.RunResult`,
        ``eoc`` (3.1) against the previous level when that is one coarser,
        and the published values as ``paper_*`` with ``l2_ratio = l2_error /
        paper_l2_error``.
    """
    table = level_sweep(scheme, "sphere", levels, **options)
    table.insert(table.columns.get_loc("iterations") + 1, "eoc", table.pop("eoc_l2_error"))
    published = pd.DataFrame.from_dict(PUBLISHED, orient="index",
                                       columns=PUBLISHED_COLUMNS)
    for column in ("l2_error", "iterations", "eoc", "cpu_seconds"):
        table[f"paper_{column}"] = table["level"].map(published[column])
    table["l2_ratio"] = table["l2_error"] / table["paper_l2_error"]
    return table


# == the pipeline's tables (Snakemake rules convergence_table, beyond_tables) ==========
#
# Everything that turns run records into tables, and tables into Markdown and
# LaTeX, lives here once: number formats, escaping, the Table 3.1 layout with
# the published values, the tables of the study beyond Table 3.1. Records are
# those of :func:`mcfbench.storage.records.read_record` (the fields of
# :class:`mcfbench.storage.records.RunResult`, ``settings``, ``provenance``).

PAPER_SCHEME = "ddfv"     # the scheme of the published Table 3.1
BASELINE = "cotan"        # wall-time ratios are taken against this scheme
MISSING = "–"             # a missing value in Markdown and HTML


# -- number formats ----------------------------------------------------------------

def _value(x):
    """``x`` as a finite float, or None."""
    if x is None or isinstance(x, bool):
        return None
    try:
        value = float(x)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def sci(x, digits=3):
    """``1.311e-02``; :data:`MISSING` for None or NaN."""
    v = _value(x)
    return MISSING if v is None else f"{v:.{digits}e}"


def fix(x, digits=3):
    v = _value(x)
    return MISSING if v is None else f"{v:.{digits}f}"


def sig(x, digits=3):
    v = _value(x)
    return MISSING if v is None else f"{v:.{digits}g}"


def signed(x, digits=3):
    v = _value(x)
    return MISSING if v is None else f"{v:+.{digits}f}"


def pct(x, digits=2):
    """A relative deviation as a signed percentage: 0.0123 -> '+1.23 %'."""
    v = _value(x)
    return MISSING if v is None else f"{100 * v:+.{digits}f} %"


def pct0(x):
    """A tolerance as a percentage: 0.01 -> '1 %'."""
    v = _value(x)
    return MISSING if v is None else f"{100 * v:g} %"


def num(x):
    """A number with ``%g``, other values as text."""
    if isinstance(x, bool) or x is None:
        return MISSING if x is None else str(x)
    if isinstance(x, (int, float)):
        return f"{x:g}"
    return str(x)


def int_or(x, fallback=None):
    """``x`` (else ``fallback``) rounded to a whole number, or :data:`MISSING`."""
    v = _value(x)
    if v is None:
        v = _value(fallback)
    return MISSING if v is None else str(int(round(v)))


def md_cell(text):
    """Text for a Markdown table cell: pipes escaped, no line breaks."""
    return str("" if text is None else text).replace("|", "\\|").replace("\n", " ")


def md_table(header, rows):
    """A Markdown pipe table, the first column left-aligned, the others right."""
    lines = ["| " + " | ".join(md_cell(h) for h in header) + " |",
             "|" + "|".join("---" if i == 0 else "---:" for i in range(len(header))) + "|"]
    lines += ["| " + " | ".join(md_cell(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


# -- LaTeX -----------------------------------------------------------------------------

_TEX_SPECIAL = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#",
                "_": r"\_", "{": r"\{", "}": r"\}", "~": r"\textasciitilde{}",
                "^": r"\textasciicircum{}", "<": r"\ensuremath{<}", ">": r"\ensuremath{>}",
                "|": r"\ensuremath{|}"}
_TEX_UNICODE = {
    "–": "--", "—": "---", "−": r"\ensuremath{-}", "×": r"\ensuremath{\times}",
    "±": r"\ensuremath{\pm}", "≤": r"\ensuremath{\le}", "≥": r"\ensuremath{\ge}",
    "≠": r"\ensuremath{\neq}", "≈": r"\ensuremath{\approx}", "∼": r"\ensuremath{\sim}",
    "√": r"\ensuremath{\surd}", "∂": r"\ensuremath{\partial}", "²": r"\ensuremath{^2}",
    "³": r"\ensuremath{^3}", "·": r"\ensuremath{\cdot}", "→": r"\ensuremath{\to}",
    "✓": r"\ensuremath{\checkmark}", "✗": r"\ensuremath{\times}",
    "○": r"\ensuremath{\circ}", "…": r"\ldots{}", "“": "``", "”": "''", "’": "'",
    "τ": r"\ensuremath{\tau}", "φ": r"\ensuremath{\varphi}", "Δ": r"\ensuremath{\Delta}",
    "χ": r"\ensuremath{\chi}", "γ": r"\ensuremath{\gamma}", "ω": r"\ensuremath{\omega}",
    "ν": r"\ensuremath{\nu}", "λ": r"\ensuremath{\lambda}", "μ": r"\ensuremath{\mu}",
    "α": r"\ensuremath{\alpha}", "β": r"\ensuremath{\beta}", "δ": r"\ensuremath{\delta}",
    "ρ": r"\ensuremath{\rho}", "κ": r"\ensuremath{\kappa}", "π": r"\ensuremath{\pi}",
}


def tex_escape(text):
    """Plain text as LaTeX: special characters escaped, common Unicode as commands
    (anything else beyond Latin-1 becomes ``?``)."""
    out = []
    for ch in str(text):
        if ch in _TEX_SPECIAL:
            out.append(_TEX_SPECIAL[ch])
        elif ch in _TEX_UNICODE:
            out.append(_TEX_UNICODE[ch])
        elif ord(ch) > 255:
            out.append("?")
        else:
            out.append(ch)
    return "".join(out)


_INLINE = re.compile(r"`([^`]+)`|<code>(.*?)</code>|\*\*(.+?)\*\*|(?<![\w*])\*([^*\s][^*]*?)\*"
                     r"|!\[([^\]]*)\]\([^)]*\)|\[([^\]]+)\]\([^)]*\)|<sub>(.*?)</sub>"
                     r"|<sup>(.*?)</sup>|<[^>]+>", re.S)


def _unescape(text):
    return (text.replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&")
            .replace("\\|", "|"))


def tex_inline(text):
    """Inline Markdown (code, bold, emphasis, links, sub/superscripts) as LaTeX."""
    out, pos = [], 0
    for m in _INLINE.finditer(text):
        out.append(tex_escape(_unescape(text[pos:m.start()])))
        code = m[1] if m[1] is not None else m[2]
        if code is not None:
            # no "--" ligature (an en dash in some fonts) inside commands
            code = re.sub(r"-(?=-)", "-{}", tex_escape(_unescape(code)))
            out.append(r"\texttt{" + code + "}")
        elif m[3] is not None:
            out.append(r"\textbf{" + tex_inline(m[3]) + "}")
        elif m[4] is not None:
            out.append(r"\emph{" + tex_inline(m[4]) + "}")
        elif m[5] is not None:
            out.append(tex_inline(m[5]))
        elif m[6] is not None:
            out.append(tex_inline(m[6]))
        elif m[7] is not None:
            out.append(r"\ensuremath{_{\mathrm{" + tex_escape(m[7]) + "}}}")
        elif m[8] is not None:
            out.append(r"\ensuremath{^{\mathrm{" + tex_escape(m[8]) + "}}}")
        pos = m.end()
    out.append(tex_escape(_unescape(text[pos:])))
    return "".join(out)


_SCI = re.compile(r"^(-?\d\.\d+)e([+-]\d+)$")


def tex_number(text):
    """A formatted cell as LaTeX: ``'1.311e-02'`` -> ``$1.311\\cdot 10^{-2}$``,
    :data:`MISSING` -> ``--``, other text through :func:`tex_inline`."""
    text = str(text)
    match = _SCI.match(text)
    if match:
        return f"${match[1]}\\cdot 10^{{{int(match[2])}}}$"
    if text == MISSING:
        return "--"
    return tex_inline(text)


_TEX_WORDS = {"n_V": "$n_V$", "n_F": "$n_F$", "n_T": "$n_T$", "tau": r"$\tau$", "h": "$h$",
              "N": "$N$", "L2": "$L_2$", "t_f": "$t_f$"}


def tex_header(text):
    """A column header as LaTeX: ``n_V``, ``tau``, ``L2``, ``t_f``, ... as math."""
    return " ".join(_TEX_WORDS.get(word, tex_inline(word)) for word in str(text).split(" "))


def tex_tabular(header, rows, spec=None, resize=True):
    """A booktabs ``tabular`` of cells already in LaTeX, centred and shrunk to
    the line width when wider."""
    spec = spec or "l" * len(header)
    lines = [rf"\begin{{tabular}}{{{spec}}}", r"\toprule", " & ".join(header) + r" \\",
             r"\midrule"]
    lines += [" & ".join(r) + r" \\" for r in rows]
    lines += [r"\bottomrule", r"\end{tabular}"]
    table = "\n".join(lines)
    if resize:
        table = "\\resizebox{\\ifdim\\width>\\linewidth\\linewidth\\else\\width\\fi}{!}{%\n" \
                + table + "}"
    return "{\\centering\\footnotesize\n" + table + "\\par}"


def tex_table(header, rows, caption, label):
    """A floating table of formatted cells (:func:`tex_header`, :func:`tex_number`);
    ``caption`` is LaTeX."""
    return "\n".join([
        r"\begin{table}[ht]", rf"\caption{{{caption}}}", rf"\label{{{label}}}",
        tex_tabular([tex_header(h) for h in header],
                    [[tex_number(c) for c in row] for row in rows],
                    "l" + "r" * (len(header) - 1)),
        r"\end{table}"])


def csv_text(table):
    """A table as CSV, floats in their shortest round-trip form (exact and
    deterministic: two runs differ in the timing columns only)."""
    return table.to_csv(index=False, lineterminator="\n")


# -- Table 3.1 and the level tables ----------------------------------------------------

LEVEL_COLUMNS = ["scheme", "label", "level", "h", "nV", "nF", "nT", "tau", "N", "l2_error",
                 "eoc", "iterations", "cpu_seconds", "wall_seconds", "wall_time_ratio",
                 "status", "t_failed", "t_min_barycentric", "paper_l2_error", "paper_eoc",
                 "paper_iterations", "paper_cpu_seconds", "l2_ratio", "message"]


def label(scheme):
    """The registry's label of ``scheme`` (the name itself if it is not registered)."""
    try:
        return get_scheme(scheme).label
    except ValueError:
        return scheme


def eoc_column(levels, l2_error, status):
    """EOC (3.1) of each row against the previous one, where it means something.

    Parameters
    ----------
    levels : (k,) int array_like
        Refinement levels of the rows, ascending.
    l2_error : (k,) float array_like
    status : (k,) str array_like

    Returns
    -------
    (k,) float array
        ``log2(e_{j-1} / e_j)`` where row ``j - 1`` is one level coarser and
        both runs finished (``status == "ok"``, finite error); NaN elsewhere,
        so that no order is ever taken against a run that broke down.

    Examples
    --------
    >>> eoc_column([1, 2, 3, 4], [1e-2, 2.5e-3, float("nan"), 4e-4],
    ...            ["ok", "ok", "t_escaped", "ok"]).round(3).tolist()
    [nan, 2.0, nan, nan]
    """
    levels = np.asarray(levels)
    ok = (np.asarray(status) == "ok") & np.isfinite(np.asarray(l2_error, dtype=float))
    errors = np.where(ok, np.asarray(l2_error, dtype=float), np.nan)
    valid = np.r_[False, (np.diff(levels) == 1) & ok[1:] & ok[:-1]]
    return np.where(valid, eoc(errors), np.nan)


def record_rows(records, schemes, levels):
    """``records[(scheme, level)]`` as a DataFrame in row order, with ``label``
    and the ``t_final`` of each record's settings."""
    rows = []
    for scheme in schemes:
        for level in levels:
            r = records[scheme, level]
            rows.append({**{k: v for k, v in r.items() if k not in ("series", "provenance")},
                         "label": label(scheme), "t_final": r["settings"]["t_final"]})
    return pd.DataFrame(rows)


def level_table(records, schemes, levels, paper_schemes=(PAPER_SCHEME,), baseline=BASELINE):
    """One row per (scheme, level) with EOC (3.1), the published values and ratios.

    Parameters
    ----------
    records : dict
        ``(scheme, level) -> run record``.
    schemes : list
        Row order.
    levels : list or dict
        Row order within a scheme: the levels of every scheme, or scheme ->
        its levels (the beyond study runs its finest level for some schemes
        only).
    paper_schemes : collection of str
        Schemes compared with the published Table 3.1 (default: the paper's
        scheme; the beyond study adds the other DDFV schemes).
    baseline : str
        ``wall_time_ratio`` is the wall time over that of this scheme on the
        same level (NaN when it did not run).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`LEVEL_COLUMNS`.
    """
    published = pd.DataFrame.from_dict(PUBLISHED, orient="index", columns=PUBLISHED_COLUMNS)
    parts = []
    for scheme in schemes:
        part = record_rows(records, [scheme],
                           levels[scheme] if isinstance(levels, dict) else levels)
        part["eoc"] = eoc_column(part["level"], part["l2_error"], part["status"])
        for column in ("l2_error", "eoc", "iterations", "cpu_seconds"):
            values = part["level"].map(published[column]) if scheme in paper_schemes \
                else np.nan
            part[f"paper_{column}"] = np.asarray(values, dtype=float)
        part["paper_iterations"] = part["paper_iterations"].astype("Int64")
        part["l2_ratio"] = part["l2_error"] / part["paper_l2_error"]
        parts.append(part)
    table = pd.concat(parts, ignore_index=True)
    if baseline in schemes:
        base = table[table["scheme"] == baseline].set_index("level")["wall_seconds"]
        table["wall_time_ratio"] = table["wall_seconds"] / table["level"].map(base)
    else:
        table["wall_time_ratio"] = np.nan
    return table[LEVEL_COLUMNS]


def l2_cell(row, digits=3):
    """The L2 error of a row, or where the run broke down."""
    if row.status != "ok":
        return f"failed (t = {row.t_failed:.4g})"
    return sci(row.l2_error, digits)


def paper_rows(table):
    """Table 3.1 as published next to ours (:data:`PAPER_SCHEME` rows)."""
    header = ["level", "n_V", "n_F", "n_T", "tau", "N", "L2 paper", "L2 ours", "ours/paper",
              "EOC paper", "EOC ours", "iter paper", "iter ours", "CPU s paper",
              "CPU s ours", "status"]
    rows = [[str(r.level), str(r.nV), str(r.nF), str(r.nT), f"{r.tau:g}", str(r.N),
             sci(r.paper_l2_error, 2), l2_cell(r), fix(r.l2_ratio, 3), fix(r.paper_eoc, 2),
             fix(r.eoc, 3), int_or(r.paper_iterations), str(r.iterations),
             fix(r.paper_cpu_seconds, 2), sig(r.cpu_seconds, 3), r.status]
            for r in table[table["scheme"] == PAPER_SCHEME].itertuples()]
    return header, rows


def comparison_rows(table, schemes, baseline=BASELINE):
    """The schemes side by side per level, with wall-time ratios to ``baseline``."""
    header = ["level", "h", "tau", "N"]
    for s in schemes:
        name = label(s)
        header += [f"{name} n_V", f"{name} L2", f"{name} EOC", f"{name} iter",
                   f"{name} wall s"]
    others = [s for s in schemes if s != baseline] if baseline in schemes else []
    header += [f"wall {label(s)}/{label(baseline)}" for s in others]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = by.loc[(schemes[0], level)]
        row = [str(level), f"{first.h:.4f}", f"{first.tau:g}", str(first.N)]
        for s in schemes:
            r = by.loc[(s, level)]
            row += [str(r.nV), l2_cell(r), fix(r.eoc, 3), str(r.iterations),
                    sig(r.wall_seconds, 3)]
        row += [fix(by.loc[(s, level)].wall_time_ratio, 2) for s in others]
        rows.append(row)
    return header, rows


def failure_notes(table):
    """One sentence per run of ``table`` that did not finish."""
    return [f"{label(r.scheme)} level {r.level}: {r.status} at t = {r.t_failed:g}: "
            f"{r.message}" for r in table[table["status"] != "ok"].itertuples()]


def _notes_md(notes):
    return ["## Runs that did not finish", ""] + [f"- {n}" for n in notes] + [""] \
        if notes else []


def _notes_tex(notes):
    return ["% runs that did not finish:"] + [f"% {n}" for n in notes] if notes else []


def convergence_documents(table, schemes, settings):
    """Table 3.1 as ``{"csv": ..., "md": ..., "tex": ...}`` texts.

    ``settings`` holds ``t_final``, ``tau_level_1`` and ``rtol``.
    """
    text = (f"Shrinking unit sphere (Section 3.1), t_f = {settings['t_final']:g}, "
            f"tau = {settings['tau_level_1']:g} / 4^(level-1), BiCGStab rtol = "
            f"{settings['rtol']:g}. L2: space-time error (3.2) (vertex schemes: over the "
            "vertices, lumped-mass weights); EOC (3.1); iter: total BiCGStab iterations; "
            "wall/CPU s: time of the flow, one BLAS thread. Timing columns differ "
            "between runs.")
    tex_text = (f"Shrinking unit sphere (Section 3.1), $t_f = {settings['t_final']:g}$, "
                f"$\\tau = {settings['tau_level_1']:g} / 4^{{k-1}}$ on level $k$, BiCGStab "
                f"tolerance {settings['rtol']:g}. $L_2$: space-time error (3.2) (vertex "
                "schemes: over the vertices, lumped-mass weights); EOC (3.1); iter: total "
                "BiCGStab iterations; CPU/wall s: time of the flow, one BLAS thread.")
    paper = PAPER_SCHEME in schemes
    notes = failure_notes(table)
    md = ["# Convergence on the shrinking sphere (Table 3.1)", "", text, ""]
    tex = ["% generated by mcfbench.presentation.tables.convergence_documents; needs booktabs, graphicx"]
    if paper:
        md += [f"## Table 3.1: published vs. reproduced ({label(PAPER_SCHEME)})", "",
               md_table(*paper_rows(table)), ""]
        tex += [tex_table(*paper_rows(table), caption="Table 3.1 as published and "
                          f"reproduced ({tex_escape(label(PAPER_SCHEME))}). " + tex_text,
                          label="tab:sphere-ddfv"), ""]
    md += ["## Schemes side by side", "", md_table(*comparison_rows(table, schemes)), ""]
    tex += [tex_table(*comparison_rows(table, schemes),
                      caption="Schemes side by side on the shrinking sphere.",
                      label="tab:sphere-schemes")]
    return {"csv": csv_text(table), "md": "\n".join(md + _notes_md(notes)),
            "tex": "\n".join(tex + _notes_tex(notes)) + "\n"}


# -- beyond Table 3.1: the T monitor, stability, orders in time and space --------------

MONITOR_COLUMNS = ["t_reached", "t_monitor_start", "t_monitor_end", "t_exit"]
BEYOND_LEVEL_COLUMNS = LEVEL_COLUMNS[:-1] + ["peak_rss_mb"] + MONITOR_COLUMNS + ["message"]
STABILITY_COLUMNS = ["study", "scheme", "label", "level", "nT", "tau", "t_final", "N",
                     "status", "t_failed", "t_reached", "t_monitor_start",
                     "t_min_barycentric", "t_monitor_end", "t_exit", "l2_error",
                     "iterations", "wall_seconds", "message"]
SPACE_COLUMNS = ["scheme", "label", "level", "h", "nV", "nF", "nT", "tau", "t_final", "N",
                 "l2_error", "eoc", "iterations", "wall_seconds", "status", "t_failed",
                 "t_min_barycentric", "message"]
TIME_COLUMNS = ["scheme", "label", "level", "t_final", "reference_tau", "tau", "N", "error",
                "order", "l2_error", "status", "message"]
SERIES_COLUMNS = ["study", "scheme", "label", "level", "tau", "t_final", "status", "n", "t",
                  "t_monitor"]


def monitor_summary(record):
    """What the T monitor of one run did.

    Returns
    -------
    dict
        ``t_reached`` (last time level computed: for a run stopped by an
        invalid state, e.g. ``t_escaped``, that state; after a solver failure
        the last state before it), ``t_monitor_start`` (at n = 0),
        ``t_monitor_end`` (at ``t_reached``), ``t_exit`` (first time a T-vertex
        was outside its triangle: the monitor < 0, or the breakdown when the
        status is ``t_escaped``; NaN if never). The monitor values are NaN for
        schemes without T-vertices.
    """
    series = record["series"]
    t = np.asarray(series["t"], dtype=float)
    monitor = np.asarray(series["t_min_barycentric"], dtype=float)
    outside = np.flatnonzero(monitor < 0)
    exit_time = t[outside[0]] if len(outside) else (
        record["t_failed"] if record["status"] == "t_escaped" else np.nan)
    return {"t_reached": float(t[-1]), "t_monitor_start": float(monitor[0]),
            "t_monitor_end": float(monitor[-1]), "t_exit": float(exit_time)}


def monitor_series(records, study):
    """The T monitor at every time level of the runs with T-vertices, long format."""
    frames = []
    for r in records:
        if r["nT"] == 0:
            continue
        monitor = np.asarray(r["series"]["t_min_barycentric"], dtype=float)
        frames.append(pd.DataFrame({
            "study": study, "scheme": r["scheme"], "label": label(r["scheme"]),
            "level": r["level"], "tau": r["tau"], "t_final": r["settings"]["t_final"],
            "status": r["status"], "n": np.arange(len(monitor)),
            "t": np.asarray(r["series"]["t"], dtype=float), "t_monitor": monitor}))
    return pd.concat(frames, ignore_index=True) if frames else \
        pd.DataFrame(columns=SERIES_COLUMNS)


def beyond_level_table(records, levels, paper_schemes):
    """:func:`level_table` of every scheme with the peak memory of each run and the
    T monitor (:func:`monitor_summary`); ``levels``: scheme -> its levels."""
    table = level_table(records, list(levels), levels, paper_schemes=set(paper_schemes))
    summary = pd.DataFrame([{"peak_rss_mb": records[s, lv]["peak_rss_mb"],
                             **monitor_summary(records[s, lv])}
                            for s, lv in zip(table["scheme"], table["level"])])
    return pd.concat([table, summary], axis=1)[BEYOND_LEVEL_COLUMNS]


def stability_table(level_records, long_records):
    """One row per run with T-vertices: the levels study, then the long runs."""
    rows = []
    for study, records in (("levels", level_records), ("long_time", long_records)):
        for r in records:
            if r["nT"] == 0:
                continue
            rows.append({**{k: v for k, v in r.items() if k in STABILITY_COLUMNS},
                         "study": study, "label": label(r["scheme"]),
                         "t_final": r["settings"]["t_final"], **monitor_summary(r)})
    return pd.DataFrame(rows, columns=STABILITY_COLUMNS)


def space_table(records, schemes, levels):
    """Order in space: one row per (scheme, level), EOC between finished runs."""
    parts = []
    for scheme in schemes:
        part = record_rows(records, [scheme], levels)
        part["eoc"] = eoc_column(part["level"], part["l2_error"], part["status"])
        parts.append(part)
    return pd.concat(parts, ignore_index=True)[SPACE_COLUMNS]


def time_order(taus, errors, status):
    """Order ``log(e_{j-1} / e_j) / log(tau_{j-1} / tau_j)`` between finished runs.

    (3.1) with tau for h; NaN for the first row and next to a run that broke
    down. For halved time steps it is the ``eoc`` of
    :func:`mcfbench.running.run.time_convergence`.
    """
    taus = np.asarray(taus, dtype=float)
    ok = (np.asarray(status) == "ok") & np.isfinite(np.asarray(errors, dtype=float))
    e = np.where(ok, np.asarray(errors, dtype=float), np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        order = np.r_[np.nan, np.log(e[:-1] / e[1:]) / np.log(taus[:-1] / taus[1:])]
    return np.where(np.r_[False, ok[1:] & ok[:-1]], order, np.nan)


def time_table(records):
    """Order in time: one row per (scheme, tau); a failed reference is one row
    with status ``reference_failed``."""
    parts = []
    for r in records:
        base = {"scheme": r["scheme"], "label": label(r["scheme"]), "level": r["level"],
                "t_final": r["t_final"], "reference_tau": r["reference_tau"]}
        if r["outcome"] != "ok":
            parts.append(pd.DataFrame([{**base, "tau": np.nan, "N": np.nan, "error": np.nan,
                                        "order": np.nan, "l2_error": np.nan,
                                        "status": r["outcome"], "message": r["message"]}]))
            continue
        rows = pd.DataFrame(r["rows"])
        for column in ("tau", "error", "l2_error"):
            rows[column] = pd.to_numeric(rows[column], errors="coerce").astype(float)
        part = rows.assign(**base, message="")
        part["order"] = time_order(part["tau"], part["error"], part["status"])
        parts.append(part)
    table = pd.concat(parts, ignore_index=True)
    table["N"] = table["N"].astype("Int64")
    return table[TIME_COLUMNS]


def beyond_tables(inputs, records, beyond, paper_schemes):
    """Every table of the beyond study from checked records.

    Parameters
    ----------
    inputs : dict
        Study (``levels``, ``long_time``, ``space``, ``time``) -> record paths.
    records : dict
        Path -> record.
    beyond : dict
        The normalised config key ``beyond`` (:func:`mcfbench.pipeline.beyond_settings`).
    paper_schemes : list of str
        Schemes compared with the published values.

    Returns
    -------
    tables : dict
        ``levels``, ``stability``, ``time_convergence``, ``space_convergence``.
    series : pandas.DataFrame
        The T monitor of the levels and long runs (:func:`monitor_series`).
    """
    by_level = {(records[p]["scheme"], records[p]["level"]): records[p]
                for p in inputs["levels"]}
    # the levels each scheme ran: beyond.levels, and beyond.finest.level for some
    runs = {s: sorted(lv for scheme, lv in by_level if scheme == s) for s in beyond["schemes"]}
    levels = [by_level[s, lv] for s, scheme_levels in runs.items() for lv in scheme_levels]
    long = [records[p] for p in inputs["long_time"]]
    space = {(records[p]["scheme"], records[p]["level"]): records[p] for p in inputs["space"]}
    tables = {
        "levels": beyond_level_table(by_level, runs, paper_schemes),
        "stability": stability_table(levels, long),
        "time_convergence": time_table([records[p] for p in inputs["time"]]),
        "space_convergence": space_table(space, beyond["space_study"]["schemes"],
                                         beyond["space_study"]["levels"]),
    }
    series = pd.concat([monitor_series(levels, "levels"), monitor_series(long, "long_time")],
                       ignore_index=True)
    return tables, series


def beyond_levels_rows(table, schemes, paper_schemes):
    """L2 and EOC per level, the schemes side by side, the paper first."""
    header = ["level", "h", "tau", "N", "L2 paper", "EOC paper"]
    for s in schemes:
        header += [f"{label(s)} L2", f"{label(s)} EOC"] + \
            ([f"{label(s)}/paper"] if s in paper_schemes else [])
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = table[table["level"] == level].iloc[0]
        paper = table[(table["level"] == level) & table["paper_l2_error"].notna()]
        row = [str(level), f"{first.h:.4f}", f"{first.tau:g}", str(first.N),
               sci(paper["paper_l2_error"].iloc[0], 2) if len(paper) else MISSING,
               fix(paper["paper_eoc"].iloc[0], 2) if len(paper) else MISSING]
        for s in schemes:
            width = 3 if s in paper_schemes else 2
            if (s, level) not in by.index:          # a level this scheme did not run
                row += [MISSING] * width
                continue
            r = by.loc[(s, level)]
            row += [l2_cell(r, 4), fix(r.eoc, 3), fix(r.l2_ratio, 3)][:width]
        rows.append(row)
    return header, rows


def cost_rows(table, schemes):
    """Iterations, CPU and wall seconds and peak memory per level and scheme."""
    header = ["level", "N"]
    for s in schemes:
        header += [f"{label(s)} iter", f"{label(s)} CPU s", f"{label(s)} wall s",
                   f"{label(s)} peak MB"]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        row = [str(level), str(table[table["level"] == level].iloc[0].N)]
        for s in schemes:
            if (s, level) not in by.index:
                row += [MISSING] * 4
                continue
            r = by.loc[(s, level)]
            row += [str(r.iterations), sig(r.cpu_seconds, 3), sig(r.wall_seconds, 3),
                    int_or(r.peak_rss_mb)]
        rows.append(row)
    return header, rows


def breakdown_notes(table):
    """One sentence per run that broke down (a table with the monitor columns)."""
    lines = []
    for r in table[table["status"] != "ok"].itertuples():
        study = f" ({r.study})" if "study" in table.columns else ""
        text = (f"{label(r.scheme)} level {r.level}{study}: {r.status} at "
                f"t = {r.t_failed:.4g} (step {round(r.t_failed / r.tau)} of {r.N})")
        if np.isfinite(r.t_monitor_end):
            text += f"; T monitor {r.t_monitor_end:.3g} at t = {r.t_reached:.4g}"
            if np.isfinite(r.t_exit):
                text += f", a T-vertex outside its triangle from t = {r.t_exit:.4g}"
        lines.append(text + f". {r.message}")
    return lines


def stability_rows(table):
    header = ["study", "scheme", "level", "t_f", "N", "status", "t_failed",
              "T monitor n=0", "min T monitor", "T monitor at end", "T outside from t",
              "L2", "wall s"]
    rows = [[r.study, label(r.scheme), str(r.level), f"{r.t_final:g}", str(r.N), r.status,
             sig(r.t_failed, 4), fix(r.t_monitor_start, 3), sig(r.t_min_barycentric, 3),
             sig(r.t_monitor_end, 3), sig(r.t_exit, 4), sci(r.l2_error, 4),
             sig(r.wall_seconds, 3)] for r in table.itertuples()]
    return header, rows


def time_rows(table):
    header = ["scheme", "tau", "N", "error at t_f", "order", "L2 (3.2)", "status"]
    rows = [[label(r.scheme), sig(r.tau, 4), int_or(r.N), sci(r.error, 3), fix(r.order, 3),
             sci(r.l2_error, 3), r.status] for r in table.itertuples()]
    return header, rows


def space_rows(table, schemes):
    header = ["level", "h", "N"]
    for s in schemes:
        header += [f"{label(s)} n_V", f"{label(s)} L2", f"{label(s)} EOC"]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = by.loc[(schemes[0], level)]
        row = [str(level), f"{first.h:.4f}", str(first.N)]
        for s in schemes:
            r = by.loc[(s, level)]
            row += [str(r.nV), l2_cell(r, 4), fix(r.eoc, 3)]
        rows.append(row)
    return header, rows


def _beyond_descriptions(beyond, settings):
    time, space, long = beyond["time_study"], beyond["space_study"], beyond["long_time"]
    finest = beyond["finest"]
    return {
        "levels": (
            f"Shrinking unit sphere (Section 3.1), t_f = {settings['t_final']:g}, "
            f"tau = {settings['tau_level_1']:g} / 4^(level-1) (tau ~ h^2), BiCGStab rtol = "
            f"{settings['rtol']:g}. L2: space-time error (3.2) (vertex schemes: over the "
            "vertices, lumped-mass weights); EOC (3.1) against the next coarser level, only "
            "between runs that finished; /paper: ours over the published L2 of Table 3.1 "
            "(levels 1-5). A run that broke down shows `failed (t = time of the breakdown)`."
            + (f" Level {finest['level']} ran for "
               f"{', '.join(label(s) for s in finest['schemes'])} only (`beyond.finest`), "
               f"at BiCGStab rtol = {finest['rtol']:g} (`beyond.finest.rtol`)."
               if finest["schemes"] else "")
            + " peak MB: peak resident memory of the run's job (ru_maxrss)."),
        "stability": (
            "T monitor: smallest barycentric coordinate of any T-vertex projected into "
            "its triangle (1/3 at the barycentre; below 0 a T-vertex is outside, and the "
            "run stops with status `t_escaped`). `levels`: the runs of the L2 table (t_f as "
            f"there); `long_time`: level {long['level']} continued to t_f = "
            f"{long['t_final']:g}. 'T monitor at end': at the last time level computed (for a "
            "run stopped by an invalid state, that state; after a solver failure, the last "
            "state before it); 'T outside from t': first time a T-vertex was outside its "
            "triangle."),
        "time_convergence": (
            f"Icosphere level {time['level']} (fixed mesh), t_f = {time['t_final']:g}, "
            f"tau = {', '.join(f'{t:g}' for t in time['taus'])}. error: distance at t_f to "
            f"a reference with tau = {time['taus'][-1] / time['reference_factor']:g} on "
            "the same mesh, weighted by the scheme's quadrature weights (DDFV: the "
            "covolumes chi / 2 over F- and T-vertices; mcfbench.running.run.time_convergence); "
            "order: log(e_prev / e) / log(tau_prev / tau); L2 (3.2): against the exact "
            "sphere (space + time error)."),
        "space_convergence": (
            f"tau = {space['tau']:g} on every level, t_f = {space['t_final']:g}: the "
            "error (3.2) against the exact sphere with the time error made small; EOC "
            "(3.1) between consecutive levels."),
    }


def _markdown(title, description, tables, notes=()):
    parts = [f"# {title}", "", description, ""]
    for heading, (header, rows) in tables:
        parts += ([f"## {heading}", ""] if heading else []) + [md_table(header, rows), ""]
    return "\n".join(parts + _notes_md(notes))


def _latex(description, tables, notes=()):
    parts = ["% generated by mcfbench.presentation.tables.beyond_documents; needs booktabs, graphicx"]
    for caption, tab_label, (header, rows) in tables:
        parts += [tex_table(header, rows, caption=tex_inline(f"{caption} {description}"),
                            label=tab_label), ""]
    return "\n".join(parts + _notes_tex(notes)) + "\n"


def beyond_documents(tables, beyond, settings, paper_schemes):
    """``name -> {"csv": text, "md": text, "tex": text}`` of the beyond tables
    (:func:`beyond_tables`); ``settings`` holds ``t_final``, ``tau_level_1``, ``rtol``."""
    schemes = beyond["schemes"]
    levels, stability = tables["levels"], tables["stability"]
    time, space = tables["time_convergence"], tables["space_convergence"]
    space_schemes = list(dict.fromkeys(space["scheme"]))
    time_labels = ", ".join(label(s) for s in dict.fromkeys(time["scheme"]))
    notes = {
        "levels": breakdown_notes(levels), "stability": breakdown_notes(stability),
        "space_convergence": [f"{label(r.scheme)} level {r.level}: {r.status} at "
                              f"t = {r.t_failed:.4g}. {r.message}"
                              for r in space[space["status"] != "ok"].itertuples()],
        "time_convergence": [f"{label(r.scheme)}: {r.status}. {r.message}"
                             for r in time[time["status"] != "ok"].itertuples()]}
    desc = _beyond_descriptions(beyond, settings)
    level_rows = beyond_levels_rows(levels, schemes, paper_schemes)
    md = {
        "levels": _markdown("Beyond Table 3.1: L2 error and EOC per level and scheme",
                            desc["levels"], [
                                ("L2 error and EOC", level_rows),
                                ("Cost: BiCGStab iterations, CPU and wall seconds of the flow "
                                 "(one core; wall seconds depend on the other jobs running), "
                                 "peak memory of the job",
                                 cost_rows(levels, schemes))], notes["levels"]),
        "stability": _markdown("T-vertex stability: the T monitor of every run",
                               desc["stability"], [("", stability_rows(stability))],
                               notes["stability"]),
        "time_convergence": _markdown("Convergence in time (fixed mesh)",
                                      desc["time_convergence"], [("", time_rows(time))],
                                      notes["time_convergence"]),
        "space_convergence": _markdown("Convergence in space (fixed time step)",
                                       desc["space_convergence"],
                                       [("", space_rows(space, space_schemes))],
                                       notes["space_convergence"]),
    }
    tex = {
        "levels": _latex(desc["levels"], [
            ("L2 error and EOC per level and scheme.", "tab:beyond-levels", level_rows),
            ("Cost: BiCGStab iterations, CPU and wall seconds (one core), peak memory.",
             "tab:beyond-cost",
             cost_rows(levels, schemes))], notes["levels"]),
        "stability": _latex(desc["stability"], [("T-vertex stability.", "tab:beyond-stability",
                                                 stability_rows(stability))],
                            notes["stability"]),
        "time_convergence": _latex(desc["time_convergence"], [
            (f"Convergence in time ({time_labels}).", "tab:beyond-time", time_rows(time))],
            notes["time_convergence"]),
        "space_convergence": _latex(desc["space_convergence"], [
            ("Convergence in space.", "tab:beyond-space", space_rows(space, space_schemes))],
            notes["space_convergence"]),
    }
    return {name: {"csv": csv_text(table), "md": md[name], "tex": tex[name]}
            for name, table in tables.items()}
