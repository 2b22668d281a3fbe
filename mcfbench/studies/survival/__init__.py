"""The survival study (issue #44, item 4): every scheme on every raw mesh of the corpus
``mcfbench/data/raw_meshes`` that the intake reads, ``steps`` steps of ``tau = C (mean
edge length)^2`` (default 40 steps of 0.1 h^2): which share of the meshes each scheme
takes to the end (every step, or the flow's extinction) with the invariants holding
at every step, apart for the meshes with and without thin features (decided by the
corpus's manifest before any run, :mod:`mcfbench.geometry.thickness`), and when the
first defect came.

The worked example of adding a study (``docs/extending.md``): this folder (:mod:`.plan`,
:mod:`.tables`, :mod:`.findings`, :mod:`.aggregate`), ``workflow/rules/survival.smk``
and the config key ``survival``; its runs are specs of the run store like every
study's.
"""

ROOT = "results/survival"
"""The folder of the study's outputs."""

RUNS_TABLE = f"{ROOT}/runs.csv"
"""Mesh x scheme: one row per run."""

SUMMARY = f"{ROOT}/survival"
"""Scheme rows: the share that reached the end, ``.md`` and ``.csv``."""

FINDINGS = f"{ROOT}/findings.md"
