"""The reproduction report: Table 3.1, the figures and the beyond study against the paper
(``workflow/rules/report.smk``).

:mod:`.inputs` reads the results (tables, records, provenance) and the paper's
published values; :mod:`.checks` compares the figures' runs with their captions;
:mod:`.page` writes ``reproduction.md``, ``.html`` and the LaTeX fragments
(templates in ``paper/templates/``).
"""
