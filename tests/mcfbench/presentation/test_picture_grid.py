"""One panel of a picture grid (mcfbench.presentation.picture_grid.panel_image): the
mesh drawn alone into an image of the panel's size that covers the given extent,
so that a grid of hundreds of panels holds images, not every panel's polygons."""

import numpy as np

from mcfbench.presentation.picture_grid import PANEL_DPI, panel_image
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
