"""Table 3.1 from the run records: CSV, Markdown, LaTeX, provenance sidecar.

Called by rule ``convergence_table`` (workflow/rules/convergence.smk).
Every record is checked first (:func:`run_records.read_record`); one bad
record stops the aggregation with a message naming the file.

The CSV has one row per scheme and level, sorted in config order of the
schemes, then by level, floats written with ``%.12g``: two runs give the
same file apart from the timing columns ``cpu_seconds``, ``wall_seconds``
and ``wall_time_ratio``.
"""

import hashlib
import re
import sys

import numpy as np
import pandas as pd
from run_records import (RecordError, read_record, setup_logging,  # first: sys.path
                         write_json_atomic, write_text_atomic)

from ddfv.errors import eoc  # noqa: E402
from ddfv.provenance import provenance  # noqa: E402
from ddfv.sphere import PUBLISHED, PUBLISHED_COLUMNS  # noqa: E402
from ddfv.surfaces import icosphere  # noqa: E402
from ddfv.topology import diamond_mesh  # noqa: E402

PAPER_SCHEME = "ddfv"   # the scheme of the published Table 3.1
BASELINE = "cotan"      # wall-time ratios are taken against this scheme
LABELS = {"ddfv": "DDFV", "cotan": "cotan"}
COLUMNS = ["scheme", "variant", "level", "h", "nV", "nF", "nT", "tau", "N", "l2_error", "eoc",
           "iterations", "cpu_seconds", "wall_seconds", "wall_time_ratio", "status",
           "t_failed", "t_min_barycentric", "paper_l2_error", "paper_eoc",
           "paper_iterations", "paper_cpu_seconds", "l2_ratio", "message"]
FLOAT_FORMAT = None  # shortest round-trip repr: exact and deterministic


def mesh_size(level):
    """Mean edge length ``h`` of the unit icosphere of ``level``."""
    V, F = icosphere(level)
    a, b = diamond_mesh(F, len(V)).diamonds[:, :2].T
    return float(np.linalg.norm(V[a] - V[b], axis=1).mean())


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
    ...            ["ok", "ok", "solver_failed", "ok"]).round(3).tolist()
    [nan, 2.0, nan, nan]
    """
    levels = np.asarray(levels)
    ok = (np.asarray(status) == "ok") & np.isfinite(np.asarray(l2_error, dtype=float))
    errors = np.where(ok, np.asarray(l2_error, dtype=float), np.nan)
    valid = np.r_[False, (np.diff(levels) == 1) & ok[1:] & ok[:-1]]
    return np.where(valid, eoc(errors), np.nan)


def build_table(records, schemes, levels, paper_schemes=(PAPER_SCHEME,)):
    """One row per (scheme, level) with EOC (3.1), paper values and ratios.

    Parameters
    ----------
    records : dict
        ``(scheme, level) -> record`` (see run_records.py).
    schemes, levels : list
        Row order.
    paper_schemes : collection of str
        Schemes compared with the published Table 3.1 (default: the paper's
        scheme only; the beyond study adds the DDFV variants).

    Returns
    -------
    pandas.DataFrame
        Columns :data:`COLUMNS`. ``eoc`` is taken against the previous
        level when that is one coarser and both runs finished
        (:func:`eoc_column`); the ``paper_*`` columns and
        ``l2_ratio = l2_error / paper_l2_error`` are filled for
        ``paper_schemes`` only; ``wall_time_ratio`` is the wall time over
        that of :data:`BASELINE` on the same level.
    """
    h = {level: mesh_size(level) for level in levels}
    published = pd.DataFrame.from_dict(PUBLISHED, orient="index", columns=PUBLISHED_COLUMNS)
    parts = []
    for scheme in schemes:
        part = pd.DataFrame([records[scheme, level] for level in levels])
        part["h"] = part["level"].map(h)
        part["eoc"] = eoc_column(part["level"], part["l2_error"], part["status"])
        for column in ("l2_error", "eoc", "iterations", "cpu_seconds"):
            values = part["level"].map(published[column]) if scheme in paper_schemes else np.nan
            part[f"paper_{column}"] = np.asarray(values, dtype=float)
        part["paper_iterations"] = part["paper_iterations"].astype("Int64")
        part["l2_ratio"] = part["l2_error"] / part["paper_l2_error"]
        parts.append(part)
    table = pd.concat(parts, ignore_index=True)
    if BASELINE in schemes:
        base = table[table["scheme"] == BASELINE].set_index("level")["wall_seconds"]
        table["wall_time_ratio"] = table["wall_seconds"] / table["level"].map(base)
    else:
        table["wall_time_ratio"] = np.nan
    return table[COLUMNS]


# -- formatting ---------------------------------------------------------------

def _missing(x):
    return pd.isna(x) or not np.isfinite(x)


def _sci(x, digits):
    return "–" if _missing(x) else f"{x:.{digits}e}"


def _fix(x, digits):
    return "–" if _missing(x) else f"{x:.{digits}f}"


def _sig(x, digits):
    return "–" if _missing(x) else f"{x:.{digits}g}"


def _int(x):
    return "–" if _missing(x) else f"{int(x)}"


_SCI = re.compile(r"^(-?\d\.\d+)e([+-]\d+)$")


def _tex(text):
    """A Markdown cell as LaTeX: scientific numbers as $m \\cdot 10^{e}$."""
    if text == "–":
        return "--"
    match = _SCI.match(text)
    if match:
        return f"${match[1]}\\cdot 10^{{{int(match[2])}}}$"
    return text.replace("_", "\\_")


_TEX_WORDS = {"n_V": "$n_V$", "n_F": "$n_F$", "n_T": "$n_T$", "tau": r"$\tau$",
              "h": "$h$", "N": "$N$", "L2": "$L_2$"}


def _tex_header(text):
    return " ".join(_TEX_WORDS.get(word, word) for word in text.split(" "))


def paper_rows(table):
    """Table 3.1 as published next to ours (:data:`PAPER_SCHEME` rows)."""
    header = ["level", "n_V", "n_F", "n_T", "tau", "N", "L2 paper", "L2 ours", "ours/paper",
              "EOC paper", "EOC ours", "iter paper", "iter ours", "CPU s paper",
              "CPU s ours", "status"]
    rows = []
    for r in table[table["scheme"] == PAPER_SCHEME].itertuples():
        rows.append([str(r.level), str(r.nV), str(r.nF), str(r.nT), f"{r.tau:g}", str(r.N),
                     _sci(r.paper_l2_error, 2), l2_cell(r), _fix(r.l2_ratio, 3),
                     _fix(r.paper_eoc, 2), _fix(r.eoc, 3), _int(r.paper_iterations),
                     str(r.iterations), _fix(r.paper_cpu_seconds, 2),
                     _sig(r.cpu_seconds, 3), r.status])
    return header, rows


def comparison_rows(table, schemes):
    """The schemes side by side per level, with wall-time ratios to the baseline."""
    header = ["level", "h", "tau", "N"]
    for s in schemes:
        name = LABELS.get(s, s)
        header += [f"{name} n_V", f"{name} L2", f"{name} EOC", f"{name} iter",
                   f"{name} wall s"]
    others = [s for s in schemes if s != BASELINE] if BASELINE in schemes else []
    header += [f"wall {LABELS.get(s, s)}/{LABELS[BASELINE]}" for s in others]
    by = table.set_index(["scheme", "level"])
    rows = []
    for level in sorted(table["level"].unique()):
        first = by.loc[(schemes[0], level)]
        row = [str(level), f"{first.h:.4f}", f"{first.tau:g}", str(first.N)]
        for s in schemes:
            r = by.loc[(s, level)]
            row += [str(r.nV), l2_cell(r), _fix(r.eoc, 3), str(r.iterations),
                    _sig(r.wall_seconds, 3)]
        row += [_fix(by.loc[(s, level)].wall_time_ratio, 2) for s in others]
        rows.append(row)
    return header, rows


def l2_cell(row, digits=3):
    """The L2 error of a row, or where the run broke down."""
    if row.status != "ok":
        return f"failed (t = {row.t_failed:.4g})"
    return _sci(row.l2_error, digits)


def failure_notes(table):
    bad = table[table["status"] != "ok"]
    return [f"{LABELS.get(r.scheme, r.scheme)} level {r.level}: {r.status} at "
            f"t = {r.t_failed:g}: {r.message}" for r in bad.itertuples()]


def _md_table(header, rows):
    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join("---" if i == 0 else "---:" for i in range(len(header))) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def _tex_table(header, rows, caption, label):
    spec = "l" + "r" * (len(header) - 1)
    lines = [r"\begin{table}[ht]", r"\centering", r"\footnotesize",
             rf"\caption{{{caption}}}", rf"\label{{{label}}}",
             r"\resizebox{\textwidth}{!}{%", rf"\begin{{tabular}}{{{spec}}}", r"\toprule",
             " & ".join(_tex_header(h) for h in header) + r" \\",
             r"\midrule"]
    lines += [" & ".join(_tex(c) for c in row) + r" \\" for row in rows]
    lines += [r"\bottomrule", r"\end{tabular}}", r"\end{table}"]
    return "\n".join(lines)


def describe(settings):
    return (f"Shrinking unit sphere (Section 3.1), t_f = {settings['t_final']:g}, "
            f"tau = {settings['tau_level_1']:g} / 4^(level-1), BiCGStab rtol = "
            f"{settings['rtol']:g}. L2: space-time error (3.2) (cotan: over vertices, "
            f"lumped-mass weights); EOC (3.1); iter: total BiCGStab iterations; "
            f"wall/CPU s: time of the flow, one BLAS thread. Timing columns differ "
            f"between runs.")


def markdown(table, schemes, settings):
    parts = ["# Convergence on the shrinking sphere (Table 3.1)", "", describe(settings), ""]
    if PAPER_SCHEME in schemes:
        parts += ["## Table 3.1: published vs. reproduced (DDFV)", "",
                  _md_table(*paper_rows(table)), ""]
    parts += ["## Schemes side by side", "", _md_table(*comparison_rows(table, schemes)), ""]
    notes = failure_notes(table)
    if notes:
        parts += ["## Runs that did not finish", ""] + [f"- {n}" for n in notes] + [""]
    return "\n".join(parts)


def latex(table, schemes, settings):
    """Tables for ``\\input`` (needs booktabs and graphicx)."""
    parts = ["% generated by workflow/scripts/convergence_table.py; needs booktabs, graphicx"]
    text = (f"Shrinking unit sphere (Section 3.1), $t_f = {settings['t_final']:g}$, "
            f"$\\tau = {settings['tau_level_1']:g} / 4^{{k-1}}$ on level $k$, BiCGStab "
            f"tolerance {settings['rtol']:g}. $L_2$: space-time error (3.2) (cotan: over "
            "the vertices, lumped-mass weights); EOC (3.1); iter: total BiCGStab "
            "iterations; CPU/wall s: time of the flow, one BLAS thread.")
    if PAPER_SCHEME in schemes:
        parts += [_tex_table(*paper_rows(table), caption="Table 3.1 as published and "
                             "reproduced (DDFV). " + text, label="tab:sphere-ddfv"), ""]
    parts += [_tex_table(*comparison_rows(table, schemes),
                         caption="Schemes side by side on the shrinking sphere.",
                         label="tab:sphere-schemes")]
    notes = failure_notes(table)
    if notes:
        parts += ["% runs that did not finish:"] + [f"% {n}" for n in notes]
    return "\n".join(parts) + "\n"


def main(paths, expected, schemes, levels, settings, outputs, log_file):
    log = setup_logging(log_file)
    records, errors = {}, {}
    for path in paths:
        try:
            records[path] = read_record(path, expected[path])
        except RecordError as err:
            errors[path] = str(err)
    if errors:
        for error in errors.values():
            log.error("invalid run record: %s", error)
        log.error("aggregation stopped: %d invalid run record(s)", len(errors))
        sys.exit(1)
    table = build_table({(r["scheme"], r["level"]): r for r in records.values()},
                        schemes, levels)
    texts = {"csv": table.to_csv(index=False, float_format=FLOAT_FORMAT, lineterminator="\n"),
             "md": markdown(table, schemes, settings),
             "tex": latex(table, schemes, settings)}
    for key, text in texts.items():
        write_text_atomic(outputs[key], text)
    sidecar = provenance({"rule": "convergence_table", **settings})
    sidecar["inputs"] = {
        path: {key: rec["provenance"].get(key) for key in
               ("config_hash", "git_commit", "git_dirty", "host", "created", "blas_threads")}
        for path, rec in records.items()}
    sidecar["outputs"] = {outputs[key]: hashlib.sha256(text.encode()).hexdigest()
                          for key, text in texts.items()}
    write_json_atomic(outputs["provenance"], sidecar)
    log.info("wrote %s", ", ".join(str(outputs[k]) for k in ("csv", "md", "tex", "provenance")))
    print(texts["md"], file=sys.stderr)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main([str(p) for p in sm.input.records], sm.params.expected, list(sm.params.schemes),
         [int(level) for level in sm.params.levels], dict(sm.params.settings),
         {key: str(sm.output[key]) for key in ("csv", "md", "tex", "provenance")},
         sm.log[0])
