"""Rules convergence_records, beyond_records: check every run record before an aggregation.

A separate job, so that a bad record stops the pipeline here and the tables
of the previous good run stay in place (Snakemake removes the outputs of a
job before it runs it). Writes the checksum of every record of the study's specs
(:func:`mcfbench.storage.run_store.read_runs`: checksum, schema, a stale spec key
or code digest).
"""

from mcfbench.pipeline import expected_runs
from mcfbench.storage.atomic import json_text, write_files
from mcfbench.storage.logs import setup_logging
from mcfbench.storage.run_store import read_runs, record_path

sm = snakemake  # noqa: F821
log = setup_logging(sm.log[0])
records = read_runs(expected_runs(sm.params.expected), log)
write_files({str(sm.output[0]): json_text({record_path(s): r["checksum"]
                                           for s, r in records.items()})})
log.info("%d run records checked", len(records))
