"""Studies: one folder per study (Table 3.1, beyond, figures, matrix, gallery, report), each with the same modules by role.

Rule: the top layer of the harness: a study's ``plan`` and ``job`` may import every other subpackage;
its other modules (``aggregate``, ``tables``, ``findings``, ``plots``, ``page``) present, under the
presentation rule. Only the command line and the Snakemake glue import the studies.
"""
