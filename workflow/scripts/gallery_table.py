"""The gallery table, mesh x scheme (rule ``gallery_table``,
workflow/rules/gallery.smk; :func:`mcfbench.studies.matrix.tables.gallery_table`)."""

import logging

from mcfbench.storage.atomic import write_text
from mcfbench.storage.records import read_records
from mcfbench.studies.gallery.tables import gallery_markdown, gallery_table

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
table = gallery_table(list(read_records(sm.params.expected).values()))
write_text(sm.output.csv, table.to_csv(index=False, float_format="%.10g"))
write_text(sm.output.md, gallery_markdown(table, sm.params.plan))
logging.info("\n%s", table.to_string())
