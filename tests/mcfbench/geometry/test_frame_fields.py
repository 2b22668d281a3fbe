"""Fields of a run's saved frames for viewing (mcfbench.geometry.frame_fields): the
displacement between frames, the vertex areas and DDFV's covolumes (they tile the
surface: Section 2.2.4), and the T monitor (1/3 at the barycentres)."""

import numpy as np
import pytest

from ddfv import Flow
from mcfbench.geometry.frame_fields import ddfv_frame_fields, displacements, vertex_frame_fields
from mcfbench.geometry.metrics import area
from mcfbench.geometry.spheres import icosphere
from mcfbench.geometry.surfaces import make_surface


def test_displacement_is_the_motion_since_the_previous_frame():
    frames = np.random.default_rng(1).normal(size=(4, 5, 3))
    moved = displacements(frames)
    np.testing.assert_array_equal(moved[0], 0.0)
    np.testing.assert_allclose(np.cumsum(moved, axis=0) + frames[0], frames, atol=1e-14)
    with pytest.raises(ValueError, match=r"\(frames, n, 3\) array, got shape \(5, 3\)"):
        displacements(frames[0])


def test_vertex_areas_are_a_third_of_each_triangle_and_sum_to_the_area():
    V, F = icosphere(2)
    frames = np.stack([V, 0.5 * V])
    fields = vertex_frame_fields(frames, F)
    assert [f["vertex_area"].sum() for f in fields] == pytest.approx(
        [area(V, F), 0.25 * area(V, F)], rel=1e-12)
    np.testing.assert_allclose(fields[1]["displacement"], -0.5 * V, atol=1e-15)


def test_ddfv_covolumes_tile_a_flat_surface_twice_and_the_t_monitor_is_a_third_at_barycentres():
    """F- and T-covolumes each tile the surface once (Section 2.2.4): on a flat mesh
    with the T-vertices at the barycentres every piece lies in the plane, so each
    family's covolumes sum to the mesh's area; the monitor is 1/3 everywhere. The
    second frame (the surface doubled) has four times the covolumes."""
    V, F = make_surface("flat_patch")
    assert np.ptp(V[:, 2]) == 0.0
    flow = Flow(V, F, 0.01, t_init="barycenter")
    frame = flow.frame()
    T = frame["extra_points"]
    np.testing.assert_allclose(T, V[F].mean(axis=1), atol=1e-15)
    fields = ddfv_frame_fields(np.stack([V, 2 * V]), np.stack([T, 2 * T]), F)
    first, second = fields
    chi_f, chi_t = first["vertices"]["covolume"], first["extra_points"]["covolume"]
    assert chi_f.shape == (len(V),) and chi_t.shape == (len(F),) and (chi_t > 0).all()
    assert chi_f.sum() == pytest.approx(area(V, F), rel=1e-12)
    assert chi_t.sum() == pytest.approx(area(V, F), rel=1e-12)
    np.testing.assert_allclose(second["vertices"]["covolume"], 4 * chi_f, rtol=1e-12)
    np.testing.assert_allclose(first["triangles"]["t_monitor"], 1 / 3, atol=1e-12)
    np.testing.assert_array_equal(first["extra_points"]["t_monitor"],
                                  first["triangles"]["t_monitor"])
    np.testing.assert_allclose(second["extra_points"]["displacement"], T, atol=1e-15)


def test_ddfv_fields_refuse_t_vertices_not_one_per_triangle():
    V, F = icosphere(1)
    with pytest.raises(ValueError, match=r"one point per triangle \(80\)"):
        ddfv_frame_fields(V[None], V[None], F)
