"""A grid of mesh pictures (rows x columns of saved frames, one length scale per
column or per row), shared by the matrix's final surfaces and the gallery."""

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from mcfbench.presentation.plots import SMALLEST_TEXT  # noqa: E402
from mcfbench.storage.atomic import save_figure  # noqa: E402
from mcfbench.storage.frames import frame_mesh, surface_points  # noqa: E402

DIAMONDS_UP_TO = 1500
"""Draw the DDFV diamond mesh (T-vertices) of meshes with at most this many triangles."""

PANEL_DPI = 120
"""Resolution of one panel's image: the grid's own (its figures are saved at 120 dpi,
where the meshes were rasterized before too)."""


def frame_surface(frames, which=-1):
    """``(vertices, extra, faces)`` of a saved frame (:func:`surface_points`: ``extra``
    the DDFV T-vertices, None for vertex schemes; ``vertices`` None without frames;
    ``faces`` the frame's own, :func:`frame_mesh`)."""
    vertices, extra = surface_points(frames)
    if vertices is None or not len(vertices):
        return None, None, np.asarray(frames["faces"])
    return (np.asarray(vertices[which]),
            extra[which] if extra is not None and len(extra) else None,
            np.asarray(frame_mesh(frames, which)[1]))


def last_frames(entries, subjects, schemes, note, first_note):
    """Per subject (a problem, a mesh) its initial surface and each scheme's last
    frame, the cells of :func:`draw_grid`.

    Parameters
    ----------
    entries : dict
        ``(subject, scheme) -> (record, frames)``, ``frames`` a mapping of the
        saved arrays (``np.load`` of the npz).
    subjects, schemes : sequences of str
    note : callable
        ``note(record)``, the text under a scheme's last frame.
    first_note : callable
        ``note(record, faces)``, the text under the initial surface, taken from
        the first scheme with frames.

    Returns
    -------
    list of lists
        ``cells[k]`` for ``subjects[k]``: the initial surface, then one cell
        per scheme, ``(vertices, extra, faces, note)``, None without a run, or
        ``(None, None, None, status)`` for a run without a mesh (refused).
    """
    cells = []
    for subject in subjects:
        row = [None] * (len(schemes) + 1)
        for j, scheme in enumerate(schemes):
            entry = entries.get((subject, scheme))
            if entry is None:
                continue
            record, frames = entry
            if "faces" not in frames or not len(frames["faces"]):
                row[j + 1] = (None, None, None, record["status"])
                continue
            vertices, extra, faces = frame_surface(frames, -1)
            row[j + 1] = (vertices, extra, faces, note(record))
            if row[0] is None:
                initial, _, _ = frame_surface(frames, 0)
                row[0] = (initial, None, faces, first_note(record, faces))
        cells.append(row)
    return cells


def draw_grid(cells, row_labels, col_labels, paths, title, views=None, share="column",
              size=1.9, max_cols=None):
    """Draw ``cells[i][j] = (vertices, extra, faces, note)`` (:func:`frame_surface`)
    or None; one length scale per column (``share="column"``) or per row
    (``"row"``); each mesh an image (:func:`panel_image`).

    With ``max_cols``, a subject's row of more cells than that wraps onto as
    many lines as it needs, of equal length (20 cells at most 6 a line: 4 lines
    of 5), each panel titled with its column's label; titles and notes are
    broken at spaces to fit the panel (:func:`fitted`)."""
    from mcfbench.presentation.render import project

    rows, cols = len(row_labels), len(col_labels)
    lines = math.ceil(cols / max_cols) if max_cols and cols > max_cols else 1
    per_line = math.ceil(cols / lines)
    fig, axes = plt.subplots(rows * lines, per_line, squeeze=False,
                             figsize=(size * per_line + 0.8,
                                      (size + 0.3 * (lines > 1)) * rows * lines + 0.5))
    views = views or [(20.0, -60.0)] * cols
    width = 0.9 * 72.0 * size     # points of a panel a title or a note may take

    def axis(i, j):
        return axes[i * lines + j // per_line, j % per_line]

    def group(i, j):
        return j if share == "column" else i

    def finite(cell):
        return cell is not None and cell[0] is not None and np.isfinite(cell[0]).all() \
            and (cell[1] is None or np.isfinite(cell[1]).all())

    boxes = {}
    for i in range(rows):
        for j in range(cols):
            if finite(cells[i][j]):
                xy = project(cells[i][j][0], views[j])[0]
                boxes.setdefault(group(i, j), []).append((xy.min(axis=0), xy.max(axis=0)))
    scale = {}
    for key, bs in boxes.items():
        lo, hi = np.min([b[0] for b in bs], axis=0), np.max([b[1] for b in bs], axis=0)
        scale[key] = (0.5 * (lo + hi), 0.55 * max(max(hi - lo), 1e-12))
    for i in range(rows):
        for j in range(lines * per_line):
            if j >= cols:                 # the last line's empty places
                axis(i, j).set_axis_off()
                continue
            ax, cell = axis(i, j), cells[i][j]
            ax.set_xticks([])
            ax.set_yticks([])
            for spine in ax.spines.values():
                spine.set_visible(False)
            if i == 0 or lines > 1:
                ax.set_title(fitted(col_labels[j], width, SMALLEST_TEXT), fontsize=SMALLEST_TEXT)
            if j % per_line == 0:
                ax.set_ylabel(row_labels[i], fontsize=SMALLEST_TEXT)
            if not finite(cell):
                text = "no frame" if cell is None else cell[3] if cell[0] is None \
                    else "non-finite state"
                ax.text(0.5, 0.5, fitted(text, width, SMALLEST_TEXT), ha="center",
                        va="center", fontsize=SMALLEST_TEXT, transform=ax.transAxes)
                continue
            vertices, extra, faces, note = cell
            if extra is not None and len(faces) > DIAMONDS_UP_TO:
                extra = None  # the diamonds of a fine mesh are a solid colour at this size
            centre, half = scale[group(i, j)]
            extent = (centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half)
            ax.imshow(panel_image(vertices, extra, faces, views[j], extent, size),
                      extent=extent,
                      interpolation="antialiased")
            ax.set_xlim(*extent[:2])
            ax.set_ylim(*extent[2:])
            ax.set_aspect("equal")
            if note:
                ax.text(0.5, 0.01, fitted(note, width, SMALLEST_TEXT), ha="center",
                        va="bottom", fontsize=SMALLEST_TEXT, transform=ax.transAxes)
    fig.suptitle(title, fontsize=9)
    # the suptitle's line kept clear of the first titles; a line's notes of the next titles
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.3 / fig.get_size_inches()[1]), h_pad=1.0)
    save_figure(fig, *paths, dpi=120)


def fitted(text, width, fontsize):
    """``text`` broken at spaces into lines at most ``width`` points wide at
    ``fontsize`` (matplotlib's default font, measured as it draws it); a word
    wider than that stands on its own line."""
    from matplotlib.textpath import TextPath

    def wide(line):
        return TextPath((0, 0), line, size=fontsize).get_extents().width

    out = []
    for word in str(text).split(" "):
        if out and wide(f"{out[-1]} {word}") <= width:
            out[-1] = f"{out[-1]} {word}"
        else:
            out.append(word)
    return "\n".join(out)


def panel_image(vertices, extra, faces, view, extent, size, dpi=PANEL_DPI):
    """One mesh (``extra``: DDFV's T-vertices, their diamond mesh drawn, or None)
    drawn alone into a ``size`` x ``size`` inch RGBA image covering
    ``extent`` (x0, x1, y0, y1 in the projected plane), the figure closed at once.

    A grid of hundreds of panels keeps one image each instead of every panel's
    polygons (the full matrix's 23 x 25 grid of meshes up to 19 000 triangles
    grew past 16 GB as polygons).

    Returns
    -------
    (h, w, 4) uint8 array
    """
    from mcfbench.presentation.render import draw_mesh

    fig = plt.figure(figsize=(size, size), dpi=dpi)
    try:
        ax = fig.add_axes((0.0, 0.0, 1.0, 1.0))
        ax.set_axis_off()
        draw_mesh(ax, vertices, extra, faces, view=view,
                  points_per_unit=72.0 * size / (extent[1] - extent[0]))
        ax.set_xlim(*extent[:2])
        ax.set_ylim(*extent[2:])
        ax.set_aspect("equal")
        fig.canvas.draw()
        return np.asarray(fig.canvas.buffer_rgba()).copy()
    finally:
        plt.close(fig)


def run_note(record):
    """The time a run reached, or its status and breakdown time."""
    t = record["steps_done"] * record["tau"]
    if record["status"] == "ok":
        return f"t = {t:.3g}"
    return f"{record['status']} t = {record['t_failed']:.3g}"
