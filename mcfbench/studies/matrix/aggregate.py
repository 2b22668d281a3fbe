"""The records of the benchmark matrix into its tables: ``matrix.csv`` (the long
table), one table per problem and the summary (:mod:`mcfbench.studies.matrix.tables`)."""

from pathlib import Path

from mcfbench.presentation.formats import tex_escape
from mcfbench.presentation.tables import Table, csv, latex, markdown
from mcfbench.storage.run_store import STORE, read_runs
from mcfbench.studies.matrix import reference_accuracies
from mcfbench.studies.matrix.plan import matrix_scheme, solver_method
from mcfbench.studies.matrix.tables import (
    BELOW_ACCURACY,
    FLOAT_FORMAT,
    TIMING_NOTE,
    long_table,
    problem_table,
    summary_table,
    summary_views,
)

def problem_notes(problem, plan=None):
    """Lines under a problem's table: what it is, the exact answer, the solver."""
    from mcfbench.running.problems import get_problem

    p = get_problem(problem)
    notes = [f"Problem `{p.name}`: {p.label}. {p.description}".strip()]
    if p.exact:
        notes.append(f"Exact answer: {p.exact}.")
    if plan is not None:
        notes.append(f"Solver: {solver_method(plan, p)}, rtol {plan['rtol']:g}.")
    return notes


def documents(frame, title, caption, notes):
    """A view of the matrix (cells already text) as ``(Markdown, LaTeX)``: the
    Markdown under the heading ``title``, the LaTeX with ``caption`` under the
    table, the notes below both; text escaped as plain text."""
    table = Table.of_frame(frame, caption=caption, notes=notes)
    return (f"# {title}\n\n{markdown(table)}\n",
            latex(table, head=tex_escape, cell=tex_escape, text=tex_escape,
                  caption_below=True) + "\n")


def write_tables(table, out_dir, plan):
    """Write ``matrix.csv``, ``{problem}.md/.tex`` and ``summary.md/.tex/.csv``."""
    from mcfbench.running.schemes import scheme_label
    from mcfbench.storage.atomic import write_text

    out = Path(out_dir)
    labels = {s: scheme_label(s) for s in plan["schemes"]}
    problems = [p for p in plan["problems"] if p in set(table["problem"])]
    write_text(out / "matrix.csv", csv(table, FLOAT_FORMAT))
    for problem in problems:
        frame, metric = problem_table(table, problem, plan["schemes"], labels)
        notes = [f"Main metric: `{metric}` per level (value, or the status of a run that "
                 f"did not finish); EOC (3.1) between consecutive levels, {BELOW_ACCURACY} "
                 "where an error of the pair is within the stated accuracy of the problem's "
                 "reference."] + \
            problem_notes(problem, plan) + [TIMING_NOTE]
        md, tex = documents(frame, f"Matrix: {problem}", f"Benchmark matrix, problem {problem}",
                            notes)
        write_text(out / f"{problem}.md", md)
        write_text(out / f"{problem}.tex", tex)
    summary = summary_table(table, problems, plan["schemes"])
    write_text(out / "summary.csv", csv(summary, FLOAT_FORMAT))
    wide = summary_views(summary, table, problems, plan["schemes"], labels)
    notes = ["Each cell: the EOC (3.1) between the two finest finished levels and the "
             "finest finished level's value of the problem's main metric (in brackets "
             "after the problem), or the status and breakdown time of the coarsest run "
             f"that did not finish; EOC {BELOW_ACCURACY} where the finest error or the one "
             "before is within the stated accuracy of the problem's reference.", TIMING_NOTE]
    md, tex = documents(wide, "Matrix summary", "Benchmark matrix: summary", notes)
    write_text(out / "summary.md", md)
    write_text(out / "summary.tex", tex)
    return summary


def aggregate(expected, plan, out_dir, root=STORE):
    """The records of every planned run (``expected``: spec -> code digest; a bad or
    stale record refused, :func:`mcfbench.storage.run_store.read_runs`; ``root``: the
    run store) into the long table and its views (:func:`write_tables`); returns
    ``(table, summary)``. A run of ``NAME+STRATEGY`` on a problem whose runs all take
    that strategy is ``NAME``'s (:func:`~mcfbench.studies.matrix.plan.matrix_scheme`)."""
    records = [{**r, "scheme": matrix_scheme(r["scheme"], r["problem"])}
               for r in read_runs(expected, root=root).values()]
    table = long_table(records, plan["schemes"],
                       list(plan["problems"]), reference_accuracies(plan))
    return table, write_tables(table, out_dir, plan)
