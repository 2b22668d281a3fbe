"""The records of the beyond study into its tables and the T-monitor series
(:mod:`mcfbench.studies.beyond.tables`), written together."""

from mcfbench.studies.beyond.plan import record_fields, scaling_fit_levels, scaling_levels


def aggregate(expected, inputs, plan, settings, paper, outputs, log):
    """The tables of the study from its records, written together.

    Parameters
    ----------
    expected : dict
        Record path -> settings of every record (:func:`beyond_runs`, flattened);
        every record is checked first (:func:`mcfbench.storage.records.read_records`).
    inputs : dict
        Study (``levels``, ``long_time``, ``space``, ``time``) -> its record paths.
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
    from mcfbench.storage.records import read_records
    from mcfbench.studies.beyond.tables import beyond_documents, beyond_tables

    records = read_records(expected, log, required=record_fields)
    tables, series = beyond_tables(inputs, records, plan, paper)
    docs = beyond_documents(tables, plan, settings, paper)
    texts = {str(outputs[f"{name}_{ext}"]): text
             for name, doc in docs.items() for ext, text in doc.items()}
    texts[str(outputs["t_monitor"])] = csv(series)
    provenance = sidecar({"rule": "beyond_tables", "beyond": plan, **settings}, records, texts)
    write_files({**texts, str(outputs["provenance"]): json_text(provenance)})
    log.info("wrote %d files\n%s\n%s", len(texts) + 1, docs["levels"]["md"],
             docs["stability"]["md"])


def aggregate_scaling(expected, plan, settings, outputs, log):
    """The scaling study from its own records (``beyond_runs(...)["scaling"]``):
    its table (CSV, Markdown, LaTeX), one row per run (``points``) and the
    provenance, written together.

    Parameters
    ----------
    expected : dict
        Record path -> settings of every run of the study; every record is
        checked first (:func:`mcfbench.storage.records.read_records`).
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
    from mcfbench.storage.records import read_records
    from mcfbench.studies.beyond.tables import scaling_documents, scaling_tables

    records = read_records(expected, log, required=record_fields)
    scaling = plan["scaling"]
    points, table = scaling_tables(records,
                                   {s: scaling_levels(scaling, s) for s in scaling["schemes"]},
                                   {s: scaling_fit_levels(scaling, s) for s in scaling["schemes"]})
    doc = scaling_documents(table, plan, settings)
    texts = {str(outputs[f"scaling_{ext}"]): text for ext, text in doc.items()}
    texts[str(outputs["points"])] = csv(points)
    provenance = sidecar({"rule": "beyond_scaling", "scaling": plan["scaling"], **settings},
                         records, texts)
    write_files({**texts, str(outputs["provenance"]): json_text(provenance)})
    log.info("wrote %d files\n%s", len(texts) + 1, doc["md"])
    return points, table
