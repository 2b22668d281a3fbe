"""Presentation: what every study shares to show its results: number formats, plots, mesh pictures, movies, documents.

Rule: reads records and tables; imports ``storage``, ``geometry`` and, of ``running``, only the
declarative registries (schemes, problems, integrators); never a solver, the driver, a flow, a study or numba.
A study's own tables, findings, plots and page live in its folder (``mcfbench/studies/<study>/``).
"""
