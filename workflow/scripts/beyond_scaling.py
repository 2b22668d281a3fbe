"""Rule beyond_scaling: the scaling study (cost against size) from its own runs.

The tables are :func:`mcfbench.studies.beyond.aggregate.aggregate_scaling` (every
record checked first): ``scaling`` (CSV, Markdown, LaTeX), ``scaling_points.csv``
(one row per run), ``scaling.json`` (provenance); the figure
:func:`mcfbench.presentation.plots.scaling_figure` (PNG, PDF).
"""

from mcfbench.pipeline import code_digests
from mcfbench.presentation.plots import scaling_figure
from mcfbench.storage.atomic import write_files
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.beyond.aggregate import aggregate_scaling
from mcfbench.studies.beyond.plan import beyond_specs

sm = snakemake  # noqa: F821
plan = dict(sm.params.beyond)
specs = beyond_specs(plan, dict(sm.params.table))["scaling"]
points, table = aggregate_scaling(specs, code_digests(specs.values()), plan,
                                  dict(sm.params.settings), sm.output, setup_logging(sm.log[0]))
figure = scaling_figure(points, table, plan["scaling"]["fit_levels"])
write_files({str(sm.output[f"figure_{ext}"]): figure for ext in ("png", "pdf")})
