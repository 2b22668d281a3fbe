"""The survival study's records into its tables and findings (:func:`aggregate`)."""

from pathlib import Path

from mcfbench.presentation.tables import csv
from mcfbench.storage.atomic import write_files
from mcfbench.storage.run_store import STORE, read_runs
from mcfbench.studies.survival import FINDINGS, ROOT, RUNS_TABLE, SUMMARY
from mcfbench.studies.survival.findings import findings
from mcfbench.studies.survival.tables import runs_table, survival_markdown, survival_table


def aggregate(expected, plan, out_dir=ROOT, store=STORE):
    """The records of the plan's runs into ``runs.csv``, ``survival.md``,
    ``survival.csv`` and ``findings.md`` under ``out_dir``, all written atomically.

    Parameters
    ----------
    expected : dict
        ``{(mesh, scheme): (spec, code digest)}``; a bad or stale record is refused
        (:func:`mcfbench.storage.run_store.read_runs`, naming its file).
    plan : dict
        :func:`mcfbench.studies.survival.plan.plan`.
    out_dir, store : str
        The study's output folder and the run store.

    Returns
    -------
    (pandas.DataFrame, pandas.DataFrame)
        The runs table and the scheme table.
    """
    mesh_of = {spec: mesh for (mesh, _), (spec, _) in expected.items()}
    records = read_runs(dict(expected.values()), root=store)
    runs = runs_table([(mesh_of[spec], r) for spec, r in records.items()], plan["meshes"])
    summary = survival_table(runs, plan["schemes"])
    texts = {RUNS_TABLE: csv(runs, "%.6g"), f"{SUMMARY}.csv": csv(summary, "%.6g"),
             f"{SUMMARY}.md": survival_markdown(summary, plan), FINDINGS: findings(summary, plan)}
    write_files({str(Path(out_dir) / Path(p).relative_to(ROOT)): t for p, t in texts.items()})
    return runs, summary


def view(params, outputs):
    """The entry of the rule ``survival_tables`` (``workflow/scripts/view.py``).

    Parameters
    ----------
    params : dict
        ``plan``; ``runs``, ``[(mesh, scheme)]``, and ``expected``, their ``[(spec
        dict, code digest)]`` in the same order
        (:meth:`mcfbench.pipeline.RunStore.expected`).
    outputs : list of str
        The rule's outputs, all in the study's output folder.
    """
    from mcfbench.storage.run_store import RunSpec

    expected = {tuple(key): (RunSpec.from_dict(dict(spec)), digest)
                for key, (spec, digest) in zip(params["runs"], params["expected"], strict=True)}
    return aggregate(expected, params["plan"], out_dir=str(Path(outputs[0]).parent))
