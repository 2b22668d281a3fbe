"""Table 3.1 of the paper (Section 3.1): the shrinking sphere on each level, any scheme,
with the published values.

The study's modules (``workflow/rules/convergence.smk`` calls them):

* :mod:`.plan`: the config keys of Table 3.1 (``levels``, ``schemes``, ``rtol``,
  ``tau_level_1``, ``t_final``) checked across keys; :func:`~.plan.sphere_spec`, the
  spec of one run in the run store (the beyond study's levels and the matrix's sphere
  ask for the same);
* :mod:`.aggregate`: the records into Table 3.1 (CSV, Markdown, LaTeX,
  provenance; :mod:`.tables`).

:func:`~.job.sphere_table` is the same table computed in one process (the command
line's ``sphere-table``).
"""

TABLE = "results/tables/convergence"
"""Table 3.1: ``.csv``, ``.md``, ``.tex``, its provenance ``.csv.json`` and the check of
its records ``.records.json``."""

FIGURE = "results/figures/convergence"
"""L2 error against h: ``.png``, ``.pdf``."""
