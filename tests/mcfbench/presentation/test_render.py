"""Pictures of the diamond mesh (mcfbench/presentation/render.py)."""

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import PolyCollection

from ddfv import Flow
from ddfv.topology import diamond_mesh
from mcfbench.geometry.shapes import cylinder
from mcfbench.geometry.spheres import icosphere
from mcfbench.presentation.render import (
    DPI,
    HIGHLIGHT_COLOR,
    Panel,
    cells_centre,
    cells_points,
    diamond_faces,
    draw_mesh,
    element_centre,
    legend_handles,
    panel_row,
    project,
    rasterize_meshes,
    tracked_cells,
    view_frame,
    worst_element,
)
from mcfbench.storage.atomic import write_files

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def sphere():
    flow = Flow(*icosphere(2), 0.01)
    return flow.F.copy(), flow.T.copy(), flow.faces


def test_render_writes_non_empty_png_and_pdf(tmp_path, sphere):
    F, T, faces = sphere
    panels = [Panel(F, T, faces, label="n = 0"),
              Panel(0.8 * F, 0.8 * T, faces, label="n = 1", zoom_box=(F[0], 0.2)),
              Panel(F, T, faces, label="detail", zoom=(F[0], 0.2)),
              Panel(F, None, faces, label="primal only", note="a note")]
    png, pdf = tmp_path / "fig.png", tmp_path / "fig.pdf"
    fig = panel_row(panels)
    write_files({png: (fig, {"dpi": DPI}), pdf: (rasterize_meshes(fig), {"dpi": 2 * DPI})})
    assert png.read_bytes()[:8] == PNG_MAGIC and png.stat().st_size > 20_000
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 20_000


def test_rasterized_meshes_are_images_in_the_pdf(tmp_path, sphere):
    F, T, faces = sphere
    vector, raster = tmp_path / "vector.pdf", tmp_path / "raster.pdf"
    write_files({vector: panel_row([Panel(F, T, faces)])})
    write_files({raster: rasterize_meshes(panel_row([Panel(F, T, faces)]))})
    assert b"/Subtype /Image" in raster.read_bytes()
    assert b"/Subtype /Image" not in vector.read_bytes()


def test_open_surface_renders(tmp_path):
    flow = Flow(*cylinder(24, 8, 1.0, 0.55, "twisted"), 0.0025)
    fig = panel_row([Panel(flow.F, flow.T, flow.faces, label="cylinder")], view=(12, -60))
    png = tmp_path / "cyl.png"
    write_files({png: (fig, {"dpi": DPI})})
    assert png.stat().st_size > 10_000


def test_camera_frame_is_orthonormal_and_right_handed():
    right, up, towards = view_frame((23.0, -71.0))
    M = np.array([right, up, towards])
    np.testing.assert_allclose(M @ M.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(np.cross(right, up), towards, atol=1e-12)
    xy, depth = project(np.array([towards, -towards]), (23.0, -71.0))
    np.testing.assert_allclose(xy, 0.0, atol=1e-12)
    assert depth[0] > depth[1]


def test_diamond_faces_cut_each_triangle_into_three_with_its_orientation(sphere):
    F, T, faces = sphere
    points, tri = diamond_faces(F, T, faces)
    assert tri.shape == (3 * len(faces), 3)
    n = np.cross(points[tri[:, 1]] - points[tri[:, 0]], points[tri[:, 2]] - points[tri[:, 0]])
    assert (np.einsum("ij,ij->i", n, points[tri].mean(axis=1)) > 0).all()  # outward


def test_worst_element_finds_a_displaced_t_vertex(sphere):
    F, T, faces = sphere
    T = T.copy()
    right, up, towards = view_frame((20.0, -60.0))
    k = int(np.argmax(F[faces].mean(axis=1) @ towards))  # the triangle facing the viewer
    T[k] = F[faces[k, 0]] + 0.9 * (F[faces[k, 1]] - F[faces[k, 0]])
    assert worst_element(F, T, faces, (20.0, -60.0), by="barycentric") == k
    np.testing.assert_allclose(element_centre(F, T, faces, k, by="barycentric"), T[k])
    d = worst_element(F, T, faces, (20.0, -60.0), by="angle")
    assert k in diamond_mesh(faces).diamonds[d, 2:]
    with pytest.raises(ValueError, match="unknown measure"):
        worst_element(F, T, faces, by="volume")


def test_tracked_cells_are_the_diamonds_of_the_two_triangles(sphere):
    F, T, faces = sphere
    mesh = diamond_mesh(faces)
    d = 7
    cells = tracked_cells(faces, d)
    t1, t2 = mesh.diamonds[d, 2:]
    assert len(cells) == 5 and d in cells                 # 3 + 3 diamonds, one shared
    assert set(cells) == set(mesh.halfedges[t1]) | set(mesh.halfedges[t2])
    # their centre is the mean of the diamond centres S = (F_a + F_b + T_1 + T_2) / 4
    expected = np.mean([element_centre(F, T, faces, c) for c in cells], axis=0)
    np.testing.assert_allclose(cells_centre(F, T, faces, cells), expected, atol=1e-14)
    # corners: the 4 F-vertices of the two triangles and the T-vertices of the 6
    # triangles the 5 cells reach into (primal only: the 8 corners of those 6)
    assert cells_points(F, T, faces, cells).shape == (4 + 6, 3)
    assert cells_points(F, None, faces, cells).shape == (8, 3)


def test_tracked_cells_on_the_boundary():
    V, faces = cylinder(12, 3, 1.0, 0.5, "parallel")
    mesh = diamond_mesh(faces)
    d = int(np.flatnonzero(mesh.boundary)[0])
    cells = tracked_cells(faces, d)
    assert len(cells) == 3 and d in cells                 # the one triangle of the edge


def test_highlighted_cells_are_filled_in_the_highlight_colour(sphere):
    F, T, faces = sphere
    cells = tracked_cells(faces, 11)
    fig, ax = plt.subplots()
    draw_mesh(ax, F, T, faces, view=(90.0, 0.0), highlight=cells, smooth=False)
    (coll,) = [c for c in ax.collections if isinstance(c, PolyCollection)]
    fill = coll.get_facecolors()[0::2]                    # face paths; even rows
    hue = fill[:, 0] - fill[:, 2]                          # amber: red >> blue
    # 2 triangles (F_a, F_b, T) per inner diamond cell; the surface is grey-ish
    assert (hue > 0.3).sum() == 2 * len(cells)
    assert (np.abs(hue) < 0.15).sum() == len(fill) - 2 * len(cells)
    plt.close(fig)


def test_legend_names_what_is_drawn(sphere):
    F, T, faces = sphere
    plain = [h.get_label() for h in legend_handles([Panel(F, T, faces)])]
    assert len(plain) == 2 and plain[0].startswith("primal edges") \
        and plain[1].startswith("diamond edges")
    assert len(legend_handles([Panel(F, None, faces)])) == 1    # primal mesh only
    marked = legend_handles([Panel(F, T, faces, highlight=np.array([1, 2])),
                             Panel(F, T, faces, zoom_box=(F[0], 0.1))])
    assert [h.get_label().split()[0] for h in marked] == ["primal", "diamond", "tracked",
                                                          "region"]
    assert marked[2].get_facecolor()[:3] == pytest.approx(
        tuple(int(HIGHLIGHT_COLOR[i:i + 2], 16) / 255 for i in (1, 3, 5)))


def test_panel_row_titles_labels_and_legend(sphere):
    F, T, faces = sphere
    fig = panel_row([Panel(F, T, faces, label="n = 0\nn_V = 482, \u03c4 = 0.01"),
                     Panel(F, T, faces, label="n = 3\nn_V = 482, \u03c4 = 0.01",
                           zoom=(F[0], 0.3), highlight=tracked_cells(faces, 0))],
                    title="a title")
    axes = fig.axes
    assert [ax.get_title() for ax in axes] == ["n = 0\nn_V = 482, \u03c4 = 0.01",
                                               "n = 3\nn_V = 482, \u03c4 = 0.01"]
    assert fig._suptitle.get_text() == "a title"
    (legend,) = fig.legends
    assert len(legend.get_texts()) == 3
    # the detail shows the square of half-width 0.3 around its centre (aspect 1)
    assert np.diff(axes[1].get_xlim())[0] == pytest.approx(0.6)
    plt.close(fig)
