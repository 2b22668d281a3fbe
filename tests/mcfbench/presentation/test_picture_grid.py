"""A picture grid (mcfbench.presentation.picture_grid): one panel (panel_image) is the
mesh drawn alone into an image of the panel's size that covers the given extent,
so that a grid of hundreds of panels holds images, not every panel's polygons; the
cells (last_frames) are each subject's initial surface and every scheme's last frame."""

import numpy as np
import pytest

from mcfbench.presentation.picture_grid import PANEL_DPI, last_frames, panel_image
from mcfbench.presentation.render import project


def test_panel_is_an_image_of_the_panel_size_with_the_mesh_where_its_projection_is():
    # a unit square seen from above (elevation 90): it covers the middle half of an
    # extent twice its width
    F = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    view = (90.0, -90.0)
    xy = project(F, view)[0]
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    centre, half = 0.5 * (lo + hi), (hi - lo).max()
    extent = (centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half)
    image = panel_image(F, None, faces, view, extent, size=1.0)
    assert image.shape == (PANEL_DPI, PANEL_DPI, 4) and image.dtype == np.uint8
    drawn = (image[..., :3] < 250).any(axis=2) & (image[..., 3] > 0)
    rows, cols = np.nonzero(drawn)
    n = PANEL_DPI
    # the square spans the middle half of the panel in both directions (to a few pixels)
    assert abs(rows.min() - n / 4) <= 4 and abs(rows.max() - 3 * n / 4) <= 4
    assert abs(cols.min() - n / 4) <= 4 and abs(cols.max() - 3 * n / 4) <= 4
    assert drawn[n // 4 + 6: 3 * n // 4 - 6, n // 4 + 6: 3 * n // 4 - 6].mean() > 0.99
    assert not drawn[: n // 4 - 6].any() and not drawn[:, 3 * n // 4 + 6:].any()


def test_cells_are_the_initial_surface_and_each_schemes_last_frame():
    V = np.eye(3)
    faces = np.array([[0, 1, 2]])
    frames = {"vertices": np.stack([V, 2 * V, 3 * V]), "faces": faces}
    ok, refused = {"status": "ok"}, {"status": "invalid_mesh"}
    entries = {("a", "s1"): (refused, {"t": np.zeros(0)}), ("a", "s2"): (ok, frames),
               ("b", "s1"): (ok, {**frames, "extra_points": np.stack([V[:1]] * 3)})}
    cells = last_frames(entries, ["a", "b", "c"], ["s1", "s2"], lambda r: r["status"],
                        lambda r, f: f"{len(f)} triangle")
    (initial, none, f0, text0), refused_cell, (last, extra, f2, text2) = cells[0]
    # the initial surface from the first scheme with frames (s2): its frame 0
    np.testing.assert_array_equal(initial, V)
    assert none is None and text0 == "1 triangle" and (f0 == faces).all()
    assert refused_cell == (None, None, None, "invalid_mesh")
    np.testing.assert_array_equal(last, 3 * V)
    assert extra is None and text2 == "ok" and (f2 == faces).all()
    np.testing.assert_array_equal(cells[1][1][1], V[:1])       # DDFV's T-vertices
    assert cells[1][2] is None and cells[2] == [None, None, None]


def _grid_figure(monkeypatch, labels, subjects=("blobby.obj", "spot.obj"), **options):
    """The figure draw_grid makes of ``subjects`` x ``labels`` cells (one small mesh
    each, every fourth a breakdown's note), drawn, instead of saved; each panel's
    image a blank one (the layout is under test here, the panel above)."""
    from mcfbench.geometry.spheres import icosphere
    from mcfbench.presentation import picture_grid

    figures = []
    monkeypatch.setattr(picture_grid, "save_figure", lambda fig, *paths, **kw: figures.append(fig))
    monkeypatch.setattr(picture_grid, "panel_image",
                        lambda *args, **kw: np.full((4, 4, 4), 255, np.uint8))
    V, F = icosphere(1)
    cells = [[(0.8 * V, None, F, "solver_stagnated t = 0.0123" if j % 4 else "t = 0.04")
              for j in range(len(labels))] for _ in subjects]
    picture_grid.draw_grid(cells, list(subjects), labels, [None], "A grid", **options)
    (fig,) = figures
    fig.canvas.draw()
    return fig


def _texts(fig):
    """``(text, its box in pixels, its font size)`` of every visible text of ``fig``."""
    from matplotlib.text import Text

    renderer = fig.canvas.get_renderer()
    return [(t.get_text(), t.get_window_extent(renderer), t.get_fontsize())
            for t in fig.findobj(Text) if t.get_visible() and t.get_text().strip()]


def test_a_long_row_wraps_into_lines_of_equal_length_and_no_text_overlaps(monkeypatch):
    """The gallery's grid: a mesh's initial surface and 19 of the registry's schemes (20
    cells, titles up to 40 characters) at most 6 a line: 4 lines of 5, 5 panels and a
    margin wide (10.3 in, where the 20-column strip was 38.8 in), every panel titled
    with its whole label (broken to fit), and no two texts overlap (the strip's did)."""
    from mcfbench.presentation.plots import SMALLEST_TEXT, style
    from mcfbench.running.schemes import SCHEMES

    labels = ["initial"] + [style(s)[0] for s in list(SCHEMES)[:19]]
    assert len(labels) == 20 and max(map(len, labels)) > 30
    fig = _grid_figure(monkeypatch, labels, ["blobby.obj"], share="row", max_cols=6)
    width, height = fig.get_size_inches()
    assert width == pytest.approx(5 * 1.9 + 0.8) and height == pytest.approx(4 * 2.2 + 0.5)
    panels = [ax for ax in fig.axes if ax.axison]
    assert len(panels) == 20
    titles = [ax.get_title() for ax in panels]
    assert [t.replace("\n", " ") for t in titles] == labels
    assert any("\n" in t for t in titles)            # a long label broken, not cut
    texts = _texts(fig)
    assert len(texts) == 1 + 20 + 4 + 20                 # suptitle, titles, labels, notes
    assert min(size for _, _, size in texts) >= SMALLEST_TEXT
    clashes = [(a, b) for k, (a, box, _) in enumerate(texts) for b, other, _ in texts[k + 1:]
               if box.overlaps(other)]
    assert clashes == []
    assert all(0 <= box.x0 and box.x1 <= fig.bbox.width for _, box, _ in texts)


def test_titles_too_long_for_a_panel_break_at_spaces_to_fit():
    from mcfbench.presentation.picture_grid import fitted

    text = "DDFV, chord + redistribution, T carried"
    lines = fitted(text, 100.0, 8).split("\n")
    assert len(lines) == 2 and " ".join(lines) == text
    assert fitted(text, 1000.0, 8) == text
    assert fitted("averyveryverylongword and", 10.0, 8) == "averyveryverylongword\nand"
