"""Presentation: number formats, Markdown/LaTeX tables, plots, mesh pictures and the report.

Rule: reads records and tables; imports ``storage`` and the numba-free parts of ``geometry``, never ``running``, ``studies``, a solver, the driver or numba.
"""
