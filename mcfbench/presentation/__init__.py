"""Presentation: number formats, Markdown/LaTeX tables, plots, mesh pictures and the report.

Rule: reads records and tables; imports ``storage``, ``geometry`` and, of ``running``, only the
declarative registries of schemes and problems; never a solver, the driver, a flow, a study or numba.
"""
