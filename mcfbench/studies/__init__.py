"""Studies: one module per study (Table 3.1, beyond, figures, matrix, gallery), each with the same protocol.

Rule: the top layer of the harness: may import every other subpackage; only the command line and the Snakemake glue import it.
"""
