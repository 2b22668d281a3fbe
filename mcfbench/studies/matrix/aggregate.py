"""The records of the benchmark matrix into its tables: ``matrix.csv`` (the long
table), one table per problem and the summary (:mod:`mcfbench.studies.matrix.tables`)."""

from pathlib import Path

from mcfbench.storage.records import read_records
from mcfbench.studies.matrix.plan import solver_method
from mcfbench.studies.matrix.tables import (
    TIMING_NOTE,
    latex,
    long_table,
    markdown,
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


def write_tables(table, out_dir, plan):
    """Write ``matrix.csv``, ``{problem}.md/.tex`` and ``summary.md/.tex/.csv``."""
    from mcfbench.running.schemes import scheme_label
    from mcfbench.storage.atomic import write_text

    out = Path(out_dir)
    labels = {s: scheme_label(s) for s in plan["schemes"]}
    problems = [p for p in plan["problems"] if p in set(table["problem"])]
    write_text(out / "matrix.csv", table.to_csv(index=False, float_format="%.10g"))
    for problem in problems:
        frame, metric = problem_table(table, problem, plan["schemes"], labels)
        notes = [f"Main metric: `{metric}` per level (value, or the status of a run that "
                 f"did not finish); EOC (3.1) between consecutive levels."] + \
            problem_notes(problem, plan) + [TIMING_NOTE]
        write_text(out / f"{problem}.md", f"# Matrix: {problem}\n\n" + markdown(frame, notes))
        write_text(out / f"{problem}.tex",
                   latex(frame, f"Benchmark matrix, problem {problem}", notes))
    summary = summary_table(table, problems, plan["schemes"])
    write_text(out / "summary.csv", summary.to_csv(index=False, float_format="%.10g"))
    wide = summary_views(summary, problems, plan["schemes"], labels)
    notes = ["Each cell: the EOC (3.1) between the two finest finished levels and the "
             "finest finished level's value of the problem's main metric (in brackets "
             "after the problem), or the status and breakdown time of the coarsest run "
             "that did not finish.", TIMING_NOTE]
    write_text(out / "summary.md", "# Matrix summary\n\n" + markdown(wide, notes))
    write_text(out / "summary.tex", latex(wide, "Benchmark matrix: summary", notes))
    return summary


def aggregate(expected, plan, out_dir):
    """The records of every planned run into the long table and its views
    (:func:`write_tables`); returns ``(table, summary)``."""
    table = long_table(list(read_records(expected).values()), plan["schemes"], list(plan["problems"]))
    return table, write_tables(table, out_dir, plan)
