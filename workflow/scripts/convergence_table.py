"""Rule convergence_table: Table 3.1 from the run records (CSV, Markdown, LaTeX, provenance).

Every record is checked first (:func:`mcfbench.storage.records.read_records`: checksum,
schema, stale settings); one bad record stops the aggregation with a message
naming the file. The tables are :func:`mcfbench.presentation.convergence_tables.level_table` and
:func:`mcfbench.presentation.convergence_tables.convergence_documents`; all four files are written
together (:func:`mcfbench.storage.atomic.write_files`).
"""

from mcfbench.pipeline import record_fields
from mcfbench.presentation.convergence_tables import convergence_documents, level_table
from mcfbench.storage.atomic import json_text, write_files
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.provenance import sidecar
from mcfbench.storage.records import read_records

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
settings = dict(sm.params.settings)
records = read_records(dict(sm.params.expected), log, required=record_fields)
table = level_table({(r["scheme"], r["level"]): r for r in records.values()},
                    list(sm.params.schemes), [int(level) for level in sm.params.levels])
docs = convergence_documents(table, list(sm.params.schemes), settings)
texts = {str(sm.output[key]): docs[key] for key in ("csv", "md", "tex")}
provenance = sidecar({"rule": "convergence_table", **settings}, records, texts)
write_files({**texts, str(sm.output.provenance): json_text(provenance)})
log.info("wrote %s\n%s", ", ".join(texts), docs["md"])
