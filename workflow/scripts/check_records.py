"""Rules convergence_records, beyond_records: check every run record before an aggregation.

A separate job, so that a bad record stops the pipeline here and the tables
of the previous good run stay in place (Snakemake removes the outputs of a
job before it runs it). Writes the checksum of every record
(:func:`mcfbench.storage.records.read_records`: checksum, schema, stale settings;
the fields of :func:`mcfbench.studies.beyond.record_fields`).
"""

from mcfbench.storage.atomic import json_text, write_files
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.records import read_records
from mcfbench.studies.beyond.plan import record_fields

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
records = read_records(dict(sm.params.expected), log, required=record_fields)
write_files({str(sm.output[0]): json_text({p: r["checksum"] for p, r in records.items()})})
log.info("%d run records checked", len(records))
