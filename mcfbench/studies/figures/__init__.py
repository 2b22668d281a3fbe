"""The figures' study: the experiments of Figs. 3.1-3.8 (``workflow/rules/figures.smk``).

The experiments (runs, panels, views, captions) are declared in
:mod:`.experiments` (``EXPERIMENTS``); :mod:`.job` runs one figure's
experiment and draws it (:mod:`mcfbench.presentation.render`).
"""

from pathlib import Path

FIGURE_OUTPUTS = ("png", "pdf", "frames", "record", "csv", "plot")
"""The outputs of one figure's job (:func:`figure_outputs`, read by ``workflow/rules/figures.smk``)."""


def figure_outputs(name, results="results"):
    """Output paths of the figure ``name``: the figure (``png``, ``pdf``), the
    folder of its runs' frames (``frames``: ``<run key>.npz`` each), its record,
    the diagnostics (``csv``) and their plot."""
    root = Path(results)
    return {"png": root / "figures" / f"{name}.png", "pdf": root / "figures" / f"{name}.pdf",
            "frames": root / "runs" / "figures" / name,
            "record": root / "runs" / "figures" / f"{name}.json",
            "csv": root / "diagnostics" / f"{name}.csv",
            "plot": root / "diagnostics" / f"{name}.png"}
