"""Table 3.1 of the paper, as published and as computed by any scheme.

The experiment is the problem ``sphere`` (:mod:`mcfbench.running.problems`): level
``k`` is the icosphere refined ``k`` times with ``tau = 0.04 / 4**(k - 1)``
(``tau ~ h^2``) up to ``t_f = 0.08``, the error (3.2).
"""


import numpy as np
import pandas as pd

from mcfbench.geometry.exact import eoc
from mcfbench.presentation.formats import fix, int_or, sci, sig, tex_escape
from mcfbench.presentation.tables import Table, csv, latex, markdown
from mcfbench.running.schemes import scheme_label as label  # the labels of every table

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


# == the pipeline's tables (Snakemake rules convergence_table, beyond_tables) ==========
#
# Run records into the Table 3.1 layout with the published values, written
# by mcfbench.presentation.tables; the beyond study builds on these. Records are
# those of :func:`mcfbench.storage.records.read_record` (the fields of
# :class:`mcfbench.storage.records.RunResult`, ``settings``, ``provenance``).

PAPER_SCHEME = "ddfv"     # the scheme of the published Table 3.1
BASELINE = "cotan"        # wall-time ratios are taken against this scheme


LEVEL_COLUMNS = ["scheme", "label", "level", "h", "nV", "nF", "nT", "tau", "N", "l2_error",
                 "eoc", "iterations", "cpu_seconds", "wall_seconds", "wall_time_ratio",
                 "status", "t_failed", "t_min_barycentric", "paper_l2_error", "paper_eoc",
                 "paper_iterations", "paper_cpu_seconds", "l2_ratio", "message"]



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
    return eoc(l2_error, levels=levels, ok=np.asarray(status) == "ok")


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


def notes_markdown(notes):
    return ["## Runs that did not finish", ""] + [f"- {n}" for n in notes] + [""] \
        if notes else []


def notes_latex(notes):
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
    tex = ["% generated by mcfbench.studies.convergence.tables.convergence_documents; needs booktabs, graphicx"]
    if paper:
        published = Table(*paper_rows(table), caption="Table 3.1 as published and "
                          f"reproduced ({tex_escape(label(PAPER_SCHEME))}). " + tex_text,
                          label="tab:sphere-ddfv")
        md += [f"## Table 3.1: published vs. reproduced ({label(PAPER_SCHEME)})", "",
               markdown(published), ""]
        tex += [latex(published), ""]
    side = Table(*comparison_rows(table, schemes),
                 caption="Schemes side by side on the shrinking sphere.",
                 label="tab:sphere-schemes")
    md += ["## Schemes side by side", "", markdown(side), ""]
    tex += [latex(side)]
    return {"csv": csv(table), "md": "\n".join(md + notes_markdown(notes)),
            "tex": "\n".join(tex + notes_latex(notes)) + "\n"}
