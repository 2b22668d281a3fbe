"""The gallery table, mesh x scheme (rule ``gallery_table``,
workflow/rules/gallery.smk; :func:`mcfbench.presentation.matrix_tables.gallery_table`)."""

import logging

from mcfbench.presentation.matrix_tables import gallery_markdown, gallery_table
from mcfbench.storage.atomic import write_text
from mcfbench.storage.records import read_records

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
table = gallery_table(list(read_records(sm.params.expected).values()))
write_text(sm.output.csv, table.to_csv(index=False, float_format="%.10g"))
write_text(sm.output.md, gallery_markdown(table, sm.params.plan))
logging.info("\n%s", table.to_string())
