"""The figures' study: the experiments of Figs. 3.1-3.8 (``workflow/rules/figures.smk``).

The experiments (runs, panels, views, captions) are declared in
:mod:`.experiments` (``EXPERIMENTS``); :mod:`.job` runs one figure's
experiment and draws it (:mod:`mcfbench.presentation.render`).
"""
