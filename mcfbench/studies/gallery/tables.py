"""The gallery's table: mesh x scheme, one row per record (CSV and Markdown)."""

import numpy as np

from mcfbench.presentation.formats import formatted
from mcfbench.storage.frames import frame_mesh, surface_points
from mcfbench.presentation.tables import Table, markdown
from mcfbench.studies.matrix.tables import TIMING_BASE


GALLERY_COLUMNS = ["mesh", "scheme", "status", "steps_done", "steps", "t_failed", "min_angle",
                   "max_flipped", "t_min_barycentric", "cpu_seconds", "vertices",
                   "triangles", "h", "tau", "solver", "message"]


def initial_triangles(frames):
    """The triangles of a run's first frame (its mesh as the scheme took it), NaN for a
    run that kept no frame (its mesh refused). ``frames``: a frames file's arrays."""
    if surface_points(frames)[0] is None:
        return np.nan
    return len(frame_mesh(frames, 0)[1])


def gallery_table(records, triangles):
    """Mesh x scheme: one row per record (:data:`GALLERY_COLUMNS`).

    Parameters
    ----------
    records : list of dict
        Run records.
    triangles : list of int or float
        Each record's triangle count (:func:`initial_triangles` of its frames; NaN
        without frames). Not the record's ``nT``: that counts DDFV's T-vertices and
        is 0 for a vertex scheme.
    """
    import pandas as pd

    rows = [{"mesh": r["mesh"], "scheme": r["scheme"], "status": r["status"],
             "steps_done": int(r["steps_done"]), "steps": int(r["N"]),
             "t_failed": r["t_failed"], "min_angle": r["min_angle"],
             "max_flipped": r["max_flipped"], "t_min_barycentric": r["t_min_barycentric"],
             "cpu_seconds": r["cpu_seconds"], "vertices": int(r["nF"]),
             "triangles": nt, "h": r["h"], "tau": r["tau"],
             "solver": r["solver"], "message": r["message"]}
            for r, nt in zip(records, triangles, strict=True)]
    return pd.DataFrame(rows, columns=GALLERY_COLUMNS)


def gallery_markdown(table, plan):
    """The gallery table as Markdown: mesh x scheme, with the settings and timing note."""
    import pandas as pd

    view = pd.DataFrame({
        "mesh": table["mesh"], "scheme": table["scheme"], "status": table["status"],
        "steps": [f"{a}/{b}" for a, b in zip(table["steps_done"], table["steps"])],
        "breakdown t": [formatted(v, ".4g") for v in table["t_failed"]],
        "min angle": [formatted(v, ".3g") for v in table["min_angle"]],
        "flipped": [formatted(v, ".0f") for v in table["max_flipped"]],
        "T monitor": [formatted(v, ".3g") for v in table["t_min_barycentric"]],
        "CPU s": [formatted(v, ".3g") for v in table["cpu_seconds"]]})
    notes = [f"Every scheme on every mesh: tau = C (mean edge length)^2 with C = {plan['C']:g}, "
             f"{plan['steps']} steps, solver {plan['solver']} (rtol {plan['rtol']:g}). "
             "Min angle and flipped triangles: worst over the sampled time levels; "
             "T monitor: smallest barycentric coordinate of a T-vertex (DDFV only).",
             TIMING_BASE]
    return f"# Gallery\n\n{markdown(Table.of_frame(view, notes=notes))}\n"
