"""The benchmark matrix: every scheme on every problem over its refinement series.

One run is :func:`mcfbench.running.run.framed_run` of one (scheme, problem,
level) with the problem's own time rule and the shared solver: BiCGStab (the
paper's) on the problems with a refinement series, the robust method
(:func:`~mcfbench.studies.matrix.plan.robust_method`) on the real-world-like
meshes (``tau_rule = "mesh"``). The study's modules
(``workflow/rules/matrix.smk`` calls them):

* :mod:`.plan`: the config key ``matrix`` checked against the registries and the
  spec of every run (its record and first and last frames in the run store,
  :mod:`mcfbench.storage.run_store`; computed by :mod:`mcfbench.running.batch`);
* :mod:`.aggregate`: the records into the tables (:mod:`.tables`);
* :mod:`.findings`: ``findings.md`` from the summary table only, in words, the
  verdicts' data from :mod:`.verdicts`, each scheme beside its remeshed variant
  from :mod:`.remeshed`;
* :mod:`.plots`: the figures; :mod:`.page`: the results page (``index.html``).

The presentation modules (:mod:`.tables`, :mod:`.findings`, :mod:`.plots`,
:mod:`.page`) import no solver, driver, flow or numba; this module declares
what they share with the plan: the output paths and which problems are
real-world-like.
"""

ROOT = "results/matrix"
"""The folder of the study's outputs."""

TABLES = f"{ROOT}/tables"
"""The tables' folder (:func:`table_files`)."""

LONG_TABLE = f"{TABLES}/matrix.csv"
"""The long table: one row per run and metric."""

SUMMARY = f"{TABLES}/summary.csv"
"""Problem x scheme."""

FIGURE_NAMES = ("errors", "work_precision", "quality", "pictures")
"""The figures (:func:`figure_files`)."""

FINDINGS = f"{ROOT}/findings.md"

PAGE = f"{ROOT}/index.html"
"""The results page: the tables, figures and findings in one offline file."""


def table_files(problems):
    """The long table, ``{problem}.md/.tex`` of every problem, ``summary.md/.tex/.csv``."""
    return [LONG_TABLE, *(f"{TABLES}/{p}.{ext}" for p in problems for ext in ("md", "tex")),
            f"{TABLES}/summary.md", f"{TABLES}/summary.tex", SUMMARY]


def figure_files():
    """``{name}_{png|pdf}`` -> path of every figure of :data:`FIGURE_NAMES`."""
    return {f"{name}_{ext}": f"{ROOT}/figures/{name}.{ext}" for name in FIGURE_NAMES
            for ext in ("png", "pdf")}


def remeshed_name(scheme):
    """The name of ``scheme`` run with remeshing (``matrix.with_remeshing``):
    ``NAME+remesh``, the mesh strategy after the integrator (``cotan@bdf2`` ->
    ``cotan@bdf2+remesh``, :func:`mcfbench.running.schemes.joined_name`'s order)."""
    return f"{scheme}+remesh"


def is_mesh_problem(problem):
    """A mesh without a refinement series: ``tau ~ (mean edge)^2``, fixed steps
    (the robust solver)."""
    return getattr(problem, "tau_rule", "level") == "mesh"


def is_real_mesh(problem):
    """One of the committed real meshes with its reference answers (the problem's
    ``kind``, :data:`mcfbench.running.problem.KINDS`)."""
    return getattr(problem, "kind", "") == "real_mesh"


def is_real_world(problem):
    """A real-world-like mesh: a problem of kind ``real_world`` (a bad mesh of a
    simple surface, a scanned-like mesh) or ``real_mesh``. The recommendation asks
    that a scheme does not break down on these."""
    return getattr(problem, "kind", "") in ("real_world", "real_mesh")


def reference_accuracies(plan):
    """Problem of the plan -> the relative accuracy of its reference answer, for the
    problems whose reference is computed by schemes and states it (the committed real
    meshes: the largest ``area_accuracy / area`` over the checkpoints, the accuracy of
    their main metric ``area_error``, :mod:`mcfbench.running.real_mesh_problems`)."""
    from mcfbench.running.problems import get_problem

    out = {}
    for p in plan["problems"]:
        ref = getattr(get_problem(p), "reference", None) or {}
        pairs = [(a, v) for a, v in zip(ref.get("area_accuracy") or (), ref.get("area") or ())
                 if a is not None and v]
        if pairs:
            out[p] = max(a / abs(v) for a, v in pairs)
    return out


def mesh_problems(plan):
    """The real-world-like problems of the plan (:func:`is_real_world`)."""
    from mcfbench.running.problems import get_problem

    return [p for p in plan["problems"] if is_real_world(get_problem(p))]
