"""Each scheme beside its remeshed variant, from the matrix's tables (issue #44: "the
orders and real-mesh errors with remeshing against without").

A scheme of ``matrix.with_remeshing`` also runs as ``NAME+remesh``
(:func:`mcfbench.studies.matrix.remeshed_name`; isotropic remeshing when the
smallest angle falls below the trigger's, :mod:`mcfbench.running.remeshing`), its
own rows in every table. Per problem and pair ``(NAME, NAME+remesh)`` that both ran
(:func:`remeshing_frame`): each one's cell of the summary (EOC and finest value, or
the breakdown: :func:`mcfbench.studies.matrix.tables.summary_cell`), the ratio of
their errors on the finest level both finished, and the ratio of their CPU seconds
over the levels both ran. :func:`remeshing_section` puts it in words and one table,
every number read from that frame.
"""

import numpy as np

from mcfbench.presentation.tables import Table, markdown
from mcfbench.studies.matrix import remeshed_name
from mcfbench.studies.matrix.tables import is_error, main_runs, robust_values, summary_cell

COLUMNS = ["problem", "metric", "scheme", "remeshed", "without", "with",
           "finished_without", "finished_with", "runs", "error_level", "error_without",
           "error_with", "error_ratio", "cpu_without", "cpu_with", "cpu_ratio"]
"""Columns of :func:`remeshing_frame`."""


def remeshed_pairs(schemes):
    """``[(NAME, NAME+remesh), ...]``: every scheme of ``schemes`` whose remeshed
    variant is among them too, in the order of ``schemes``."""
    names = set(schemes)
    return [(s, remeshed_name(s)) for s in schemes if remeshed_name(s) in names]


def remeshing_frame(table, summary, pairs):
    """Each scheme against its remeshed variant, per problem.

    Parameters
    ----------
    table : pandas.DataFrame
        The long table (:func:`mcfbench.studies.matrix.tables.long_table`).
    summary : pandas.DataFrame
        Its summary with the lists behind its cells, in the scheme view
        (:func:`mcfbench.studies.matrix.verdicts.scheme_view` of
        :func:`~mcfbench.studies.matrix.tables.with_levels`).
    pairs : sequence of (str, str)
        :func:`remeshed_pairs`.

    Returns
    -------
    pandas.DataFrame
        One row per problem (summary order) and pair whose two schemes both ran it,
        columns :data:`COLUMNS`: ``without``, ``with`` (the summary's cells),
        ``finished_without``, ``finished_with`` (runs that reached their end with a
        finite value, of ``runs``, the levels both ran; a run whose failure the
        robust solver removes counts with the re-run's value, as in the verdicts:
        :func:`~mcfbench.studies.matrix.tables.robust_values`), ``error_level`` (the
        finest level both finished; NaN when none or the main metric is no error),
        ``error_without``, ``error_with`` (their magnitudes there),
        ``error_ratio`` (with / without), ``cpu_without``, ``cpu_with`` (CPU
        seconds summed over the levels both ran, the long table's ``cpu_seconds``:
        without a robust re-run's), ``cpu_ratio``.
    """
    import pandas as pd

    cells = {(r["problem"], r["scheme"]): summary_cell(r) for _, r in summary.iterrows()}
    rows = []
    for problem in dict.fromkeys(summary["problem"]):
        runs, metric = main_runs(table, problem)
        for scheme, remeshed in pairs:
            if (problem, scheme) not in cells or (problem, remeshed) not in cells:
                continue
            a = runs[runs["scheme"] == scheme].set_index("level")
            b = runs[runs["scheme"] == remeshed].set_index("level")
            both = sorted(set(a.index) & set(b.index))
            a, b = a.loc[both], b.loc[both]
            values_a, values_b = robust_values(a), robust_values(b)
            done_a, done_b = np.isfinite(values_a), np.isfinite(values_b)
            usable = np.flatnonzero(done_a & done_b)
            level = both[usable[-1]] if is_error(metric) and len(usable) else None
            error_a = abs(values_a[usable[-1]]) if level is not None else np.nan
            error_b = abs(values_b[usable[-1]]) if level is not None else np.nan
            cpu_a, cpu_b = a["cpu_seconds"].sum(), b["cpu_seconds"].sum()
            rows.append({
                "problem": problem, "metric": metric, "scheme": scheme, "remeshed": remeshed,
                "without": cells[(problem, scheme)], "with": cells[(problem, remeshed)],
                "finished_without": int(done_a.sum()), "finished_with": int(done_b.sum()),
                "runs": len(both), "error_level": np.nan if level is None else level,
                "error_without": error_a, "error_with": error_b,
                "error_ratio": error_b / error_a if error_a > 0 else np.nan,
                "cpu_without": cpu_a, "cpu_with": cpu_b,
                "cpu_ratio": cpu_b / cpu_a if cpu_a > 0 else np.nan})
    return pd.DataFrame(rows, columns=COLUMNS)


def _ratio(value):
    return "–" if not np.isfinite(value) else f"{value:.3g}"


def remeshing_table(frame):
    """The frame of :func:`remeshing_frame` as a
    :class:`~mcfbench.presentation.tables.Table`: each scheme's cell beside its
    remeshed variant's."""
    rows = [(f"{r['problem']} ({r['metric']})", r["scheme"], r["without"], r["with"],
             "–" if not np.isfinite(r["error_level"]) else f"L{int(r['error_level'])}",
             r["error_ratio"], r["cpu_ratio"]) for _, r in frame.iterrows()]
    return Table(["problem (main metric)", "scheme", "without remeshing",
                  "with remeshing (NAME+remesh)", "level compared",
                  "|error| with / without", "CPU s with / without"],
                 rows, [None, None, None, None, None, _ratio, _ratio], align="lllllrr")


def _geometric_mean(values):
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values) & (values > 0)]
    return float(np.exp(np.log(values).mean())) if len(values) else np.nan


def pair_lines(frame):
    """One line per scheme of ``frame``: the problems where its remeshed variant's
    error is smaller, equal or larger, their geometric mean ratio, the finished runs
    of both, and the CPU time of both over all their runs."""
    lines = []
    for scheme in dict.fromkeys(frame["scheme"]):
        part = frame[frame["scheme"] == scheme]
        ratios = part["error_ratio"].to_numpy(dtype=float)
        known = ratios[np.isfinite(ratios)]
        text = f"- **{scheme}** against **{part['remeshed'].iloc[0]}** on " \
            f"{len(part)} problem(s): "
        if len(known):
            text += (f"the error with remeshing is smaller on {int((known < 1).sum())}, "
                     f"larger on {int((known > 1).sum())}"
                     + (f", equal on {int((known == 1).sum())}" if (known == 1).any() else "")
                     + f" of the {len(known)} compared (geometric mean ratio "
                     f"{_geometric_mean(known):.3g})")
        else:
            text += "no finished level with an error in common"
        cpu_a, cpu_b = part["cpu_without"].sum(), part["cpu_with"].sum()
        text += (f"; finished runs {int(part['finished_without'].sum())} of "
                 f"{int(part['runs'].sum())} without, {int(part['finished_with'].sum())} "
                 f"with; CPU {cpu_a:.3g} s without, {cpu_b:.3g} s with"
                 + (f" ({cpu_b / cpu_a:.3g} x)." if cpu_a > 0 else "."))
        lines.append(text)
    return lines


def remeshing_section(frame):
    """The section "With remeshing against without": :func:`pair_lines` and the table
    (:func:`remeshing_table`); empty without a pair that ran."""
    if not len(frame):
        return []
    return ["## With remeshing against without", "",
            "Each scheme of `matrix.with_remeshing` beside its remeshed variant `NAME+remesh` "
            "(isotropic remeshing when the smallest angle falls below the trigger's, "
            "`mcfbench.running.remeshing`), on every problem both ran: the summary's cells "
            "(EOC between the two finest finished levels and the finest value, or the "
            "breakdown), the ratio of the error magnitudes on the finest level both "
            "finished (below 1: remeshing is more accurate; a run whose failure the robust "
            "solver removes counts with the re-run's value), and the ratio of the CPU "
            "seconds summed over the levels both ran (the runs' own: a robust re-run's "
            "time is not in the long table).", "",
            *pair_lines(frame), "", markdown(remeshing_table(frame)), ""]
