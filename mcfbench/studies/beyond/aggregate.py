"""The records of the beyond study into its tables and the T-monitor series
(:mod:`mcfbench.studies.beyond.tables`), written together; the time study's errors
from the saved final states of its runs (:func:`time_records`)."""

from mcfbench.studies.beyond.plan import scaling_fit_levels, scaling_levels


def read_study(specs, digests, log):
    """``{study: {key: record}}`` of ``specs`` (``{study: {key: spec}}``), every record
    checked first (:func:`mcfbench.storage.run_store.read_runs`: one bad or stale
    record stops it, each named), and ``{record path: record}`` (the provenance's
    inputs)."""
    from mcfbench.storage.run_store import read_runs, record_path

    unique = list(dict.fromkeys(s for study in specs.values() for s in study.values()))
    records = read_runs({s: digests[s] for s in unique}, log)
    return ({study: {key: records[s] for key, s in part.items()}
             for study, part in specs.items()},
            {record_path(s): records[s] for s in unique})


def time_records(specs, records, plan, root=None):
    """The time study of every scheme from its runs: one record per scheme in the shape
    of :func:`mcfbench.studies.beyond.tables.time_table`'s input (``scheme``, ``level``,
    ``t_final``, ``reference_tau``, ``outcome``, ``message``, ``rows``). Each row's
    ``error`` and ``volume_error`` compare the run's final state with the reference's
    (:func:`mcfbench.geometry.metrics.final_state_distance`, the reference's
    quadrature weights saved in its frames); a reference that broke down gives
    ``outcome = "reference_failed"`` and no rows.

    Parameters
    ----------
    specs, records : dict
        ``(scheme, tau) -> spec`` and ``-> record`` of the time study.
    plan : dict
        The beyond plan (its ``time_study``).
    root : str, optional
        The run store (default :data:`mcfbench.storage.run_store.STORE`).
    """
    import numpy as np

    from mcfbench.geometry.metrics import final_state_distance
    from mcfbench.storage.frames import load_frames
    from mcfbench.storage.run_store import STORE, frames_path
    from mcfbench.studies.beyond.plan import time_taus

    root = STORE if root is None else root

    study = plan["time_study"]
    *taus, reference_tau = time_taus(plan)
    out = []
    for scheme in study["schemes"]:
        reference = records[scheme, reference_tau]
        base = {"scheme": scheme, "level": study["level"], "taus": taus,
                "reference_factor": study["reference_factor"], "reference_tau": reference_tau,
                "t_final": study["t_final"]}
        if reference["status"] != "ok":
            out.append({**base, "outcome": "reference_failed",
                        "message": f"reference run failed: {reference['message']}",
                        "rows": []})
            continue
        ref = load_frames(frames_path(specs[scheme, reference_tau], root))
        rows = []
        for tau in taus:
            r = records[scheme, tau]
            ok = r["status"] == "ok"
            error, volume_error = final_state_distance(
                load_frames(frames_path(specs[scheme, tau], root)), ref, ref["l2_weights"]) \
                if ok else (np.nan, np.nan)
            rows.append({"tau": tau, "N": r["N"], "error": error, "volume_error": volume_error,
                         **{m: r[m] for m in r["metric_names"]}, "status": r["status"]})
        out.append({**base, "outcome": "ok", "message": "", "rows": rows})
    return out


def aggregate(specs, digests, plan, settings, paper, outputs, log):
    """The tables of the study from its records, written together.

    Parameters
    ----------
    specs : dict
        Study (``levels``, ``long_time``, ``space``, ``time``) -> key -> spec
        (:func:`mcfbench.studies.beyond.plan.beyond_specs`).
    digests : dict
        Spec -> the current code digest (:func:`mcfbench.pipeline.code_digests`).
    plan : dict
        :func:`plan`.
    settings : dict
        The Table 3.1 keys the tables depend on (``tau_level_1``, ``t_final``, ``rtol``).
    paper : list
        :func:`paper_schemes`.
    outputs : dict
        ``<table>_<csv|md|tex>`` of ``levels``, ``stability``, ``time_convergence``,
        ``space_convergence``, and ``t_monitor`` (the T monitor at every time
        level), ``provenance`` -> path.
    """
    from mcfbench.presentation.tables import csv
    from mcfbench.storage.atomic import json_text, write_files
    from mcfbench.storage.provenance import sidecar
    from mcfbench.studies.beyond.tables import beyond_documents, beyond_tables

    by_study, inputs = read_study(specs, digests, log)
    by_study["time"] = {r["scheme"]: r for r in time_records(specs["time"], by_study["time"],
                                                              plan)}
    tables, series = beyond_tables(
        {study: [(study, key) for key in part] for study, part in by_study.items()},
        {(study, key): r for study, part in by_study.items() for key, r in part.items()},
        plan, paper)
    docs = beyond_documents(tables, plan, settings, paper)
    texts = {str(outputs[f"{name}_{ext}"]): text
             for name, doc in docs.items() for ext, text in doc.items()}
    texts[str(outputs["t_monitor"])] = csv(series)
    provenance = sidecar({"rule": "beyond_tables", "beyond": plan, **settings}, inputs, texts)
    write_files({**texts, str(outputs["provenance"]): json_text(provenance)})
    log.info("wrote %d files\n%s\n%s", len(texts) + 1, docs["levels"]["md"],
             docs["stability"]["md"])


def aggregate_scaling(specs, digests, plan, settings, outputs, log):
    """The scaling study from its own records (``beyond_specs(...)["scaling"]``):
    its table (CSV, Markdown, LaTeX), one row per run (``points``) and the
    provenance, written together.

    Parameters
    ----------
    specs : dict
        (scheme, level) -> spec of every run of the study; every record is checked
        first (:func:`mcfbench.storage.run_store.read_runs`).
    digests : dict
        Spec -> the current code digest.
    plan : dict
        :func:`plan`.
    settings : dict
        ``t_final`` (named in the description).
    outputs : dict
        ``scaling_csv``, ``scaling_md``, ``scaling_tex``, ``points``,
        ``provenance`` -> path.

    Returns
    -------
    points, table : pandas.DataFrame
        :func:`mcfbench.studies.beyond.tables.scaling_tables`.
    """
    from mcfbench.presentation.tables import csv
    from mcfbench.storage.atomic import json_text, write_files
    from mcfbench.storage.provenance import sidecar
    from mcfbench.studies.beyond.tables import scaling_documents, scaling_tables

    by_study, inputs = read_study({"scaling": specs}, digests, log)
    scaling = plan["scaling"]
    points, table = scaling_tables(by_study["scaling"],
                                   {s: scaling_levels(scaling, s) for s in scaling["schemes"]},
                                   {s: scaling_fit_levels(scaling, s) for s in scaling["schemes"]})
    doc = scaling_documents(table, plan, settings)
    texts = {str(outputs[f"scaling_{ext}"]): text for ext, text in doc.items()}
    texts[str(outputs["points"])] = csv(points)
    provenance = sidecar({"rule": "beyond_scaling", "scaling": plan["scaling"], **settings},
                         inputs, texts)
    write_files({**texts, str(outputs["provenance"]): json_text(provenance)})
    log.info("wrote %d files\n%s", len(texts) + 1, doc["md"])
    return points, table
