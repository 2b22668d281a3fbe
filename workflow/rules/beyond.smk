# Beyond Table 3.1 (level 6, scheme variants, T-vertex stability study).
# Not part of `rule all`: run with `snakemake --cores 2 beyond`.
BEYOND_TARGETS = []
