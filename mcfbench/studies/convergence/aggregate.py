"""The records of Table 3.1 into its table (:mod:`mcfbench.studies.convergence.tables`)."""


def aggregate(expected, schemes, levels, settings, outputs, log):
    """Table 3.1 from the run store's records of ``expected`` (spec -> code digest):
    CSV, Markdown, LaTeX and the provenance sidecar, written together.

    Every record is checked first (:func:`mcfbench.storage.run_store.read_runs`);
    one bad or stale record stops the aggregation with a message naming the file.
    ``outputs``: ``csv``, ``md``, ``tex``, ``provenance`` -> path.

    Returns
    -------
    dict
        The documents (``csv``, ``md``, ``tex``: text).
    """
    from mcfbench.storage.atomic import json_text, write_files
    from mcfbench.storage.provenance import sidecar
    from mcfbench.storage.run_store import read_runs, record_path
    from mcfbench.studies.convergence.tables import convergence_documents, level_table

    records = read_runs(expected, log)
    table = level_table({(s.scheme, s.level): r for s, r in records.items()},
                        list(schemes), [int(level) for level in levels])
    docs = convergence_documents(table, list(schemes), settings)
    texts = {str(outputs[key]): docs[key] for key in ("csv", "md", "tex")}
    provenance = sidecar({"rule": "convergence_table", **settings},
                         {record_path(s): r for s, r in records.items()}, texts)
    write_files({**texts, str(outputs["provenance"]): json_text(provenance)})
    log.info("wrote %s\n%s", ", ".join(texts), docs["md"])
    return docs
