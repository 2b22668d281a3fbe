"""A picture grid (mcfbench.presentation.picture_grid): one panel (panel_image) is the
mesh drawn alone into an image of the panel's size that covers the given extent,
so that a grid of hundreds of panels holds images, not every panel's polygons; the
cells (last_frames) are each subject's initial surface and every scheme's last frame."""

import numpy as np

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
