"""Pictures of the diamond mesh (ddfv/render.py)."""

import numpy as np
import pytest

from ddfv import Flow, icosphere
from ddfv.render import (Panel, diamond_faces, element_centre, panel_row, project, save_figure,
                         view_frame, worst_element)
from ddfv.shapes import cylinder

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def sphere():
    flow = Flow(*icosphere(2), 0.01)
    return flow.F.copy(), flow.T.copy(), flow.mesh.faces


def test_render_writes_non_empty_png_and_pdf(tmp_path, sphere):
    F, T, faces = sphere
    panels = [Panel(F, T, faces, label="n = 0"),
              Panel(0.8 * F, 0.8 * T, faces, label="n = 1", zoom_box=(F[0], 0.2)),
              Panel(F, T, faces, label="detail", zoom=(F[0], 0.2)),
              Panel(F, None, faces, label="primal only", note="a note")]
    png, pdf = save_figure(panel_row(panels), tmp_path / "fig.png", tmp_path / "fig.pdf")
    assert png.read_bytes()[:8] == PNG_MAGIC and png.stat().st_size > 20_000
    assert pdf.read_bytes()[:5] == b"%PDF-" and pdf.stat().st_size > 20_000


def test_stem_writes_png_and_pdf(tmp_path, sphere):
    F, T, faces = sphere
    paths = save_figure(panel_row([Panel(F, T, faces)]), tmp_path / "sub" / "fig_3_1")
    assert [p.name for p in paths] == ["fig_3_1.png", "fig_3_1.pdf"]
    assert all(p.stat().st_size > 0 for p in paths)


def test_open_surface_renders(tmp_path):
    flow = Flow(*cylinder(), 0.0025)
    fig = panel_row([Panel(flow.F, flow.T, flow.mesh.faces, label="cylinder")], view=(12, -60))
    (png,) = save_figure(fig, tmp_path / "cyl.png")
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
    assert k in worst_diamond_triangles(faces, d)


def worst_diamond_triangles(faces, d):
    from ddfv.topology import diamond_mesh

    return diamond_mesh(faces).diamonds[d, 2:]
