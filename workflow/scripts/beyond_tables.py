"""Rule beyond_tables: the tables of the study beyond Table 3.1 from its records.

Every record is checked first (:func:`mcfbench.storage.records.read_records`). Writes
``levels``, ``stability``, ``time_convergence``, ``space_convergence`` (CSV,
Markdown, LaTeX each; :func:`mcfbench.presentation.beyond_tables.beyond_tables`,
:func:`mcfbench.presentation.beyond_tables.beyond_documents`), ``t_monitor.csv`` (the T monitor
at every time level) and ``beyond.json`` (provenance), all together.
"""

from mcfbench.pipeline import record_fields
from mcfbench.presentation.beyond_tables import beyond_documents, beyond_tables
from mcfbench.presentation.formats import csv_text
from mcfbench.storage.atomic import json_text, write_files
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.provenance import sidecar
from mcfbench.storage.records import read_records

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
beyond, settings, paper = dict(sm.params.beyond), dict(sm.params.settings), \
    list(sm.params.paper_schemes)
inputs = {study: [str(p) for p in sm.input[study]]
          for study in ("levels", "long_time", "space", "time")}
records = read_records(dict(sm.params.expected), log, required=record_fields)
tables, series = beyond_tables(inputs, records, beyond, paper)
docs = beyond_documents(tables, beyond, settings, paper)
texts = {str(sm.output[f"{name}_{ext}"]): text
         for name, doc in docs.items() for ext, text in doc.items()}
texts[str(sm.output.t_monitor)] = csv_text(series)
provenance = sidecar({"rule": "beyond_tables", "beyond": beyond, **settings}, records, texts)
write_files({**texts, str(sm.output.provenance): json_text(provenance)})
log.info("wrote %d files\n%s\n%s", len(texts) + 1, docs["levels"]["md"],
         docs["stability"]["md"])
