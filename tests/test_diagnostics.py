"""Mesh-quality diagnostics (ddfv/diagnostics.py)."""

import numpy as np
import pandas as pd
import pytest

from ddfv import Flow, icosphere, simulate
from ddfv.diagnostics import (COLUMNS, MeshQuality, describe_violation, diamond_min_angles,
                              first_violation, mesh_quality)
from ddfv.topology import diamond_mesh


@pytest.fixture(scope="module")
def sphere():
    """Level-2 icosphere with the paper's T-vertices."""
    flow = Flow(*icosphere(2), 0.01)
    return flow.mesh, flow.F.copy(), flow.T.copy()


def test_paper_initialisation_puts_t_vertices_near_the_barycentres(sphere):
    q = mesh_quality(*sphere)
    assert 0.32 < q["t_bary_min"] <= 1 / 3 + 1e-12
    assert q["t_bary_median"] == pytest.approx(1 / 3, abs=2e-3)
    assert 0.5 < q["diamond_area_min_rel"] <= 1.0
    # the triangles (F_a, F_b, T) of a near-equilateral mesh: angles near 30 degrees
    assert 20.0 < q["angle_min_deg"] <= 30.0 + 1e-9


def test_area_and_volume_approach_the_sphere(sphere):
    q = mesh_quality(*sphere)
    assert q["area"] == pytest.approx(4 * np.pi, rel=0.02)
    assert q["volume"] == pytest.approx(4 / 3 * np.pi, rel=0.03)


def test_t_vertex_moved_outside_its_triangle_is_found(sphere):
    mesh, F, T = sphere
    T = T.copy()
    k = 17
    a, b, c = F[mesh.faces[k]]
    T[k] = a + 1.3 * (b - a)  # beyond the vertex b, outside the triangle
    q = mesh_quality(mesh, F, T)
    assert q["t_bary_min"] < -0.2
    assert q["worst_t"] == k
    assert q["angle_min_deg"] < 0  # the diamond mesh folds over


def test_first_violation_on_an_observed_flow(sphere):
    mesh, F, T = sphere
    quality = MeshQuality()
    simulate(F, mesh.faces, 0.01, 3, T0=T, observer=quality)
    df = quality.frame()
    assert list(df.columns) == list(COLUMNS)
    assert df["n"].tolist() == [0, 1, 2, 3]
    assert first_violation(df) is None
    assert describe_violation(df) == ""
    # the same flow with one T-vertex pushed out of its triangle at n = 2
    bad = df.copy()
    bad.loc[2, ["t_bary_min", "worst_t"]] = [-0.1, 5]
    assert first_violation(bad) == 2
    assert "T-vertex 5 left its triangle" in describe_violation(bad)


def test_collapsed_diamond_and_nan_count_as_violations():
    df = pd.DataFrame({"n": [0, 1, 2, 3], "t": [0.0, 0.1, 0.2, 0.3],
                       "t_bary_min": [0.3, 0.3, 0.3, np.nan],
                       "diamond_area_min_rel": [0.8, 0.5, 1e-9, 0.5],
                       "worst_t": [0, 0, 0, 0], "worst_diamond": [1, 2, 3, 4]})
    assert first_violation(df) == 2
    assert "diamond 3 collapsed" in describe_violation(df)
    assert first_violation(df.iloc[[0, 1, 3]]) == 3
    assert first_violation(df.iloc[[0, 1]]) is None


def test_diamond_min_angles_of_a_regular_configuration():
    # a flat square split by its diagonal, T-vertices at the barycentres
    F = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.0]])
    faces = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    mesh = diamond_mesh(faces)
    T = F[faces].mean(axis=1)
    angles = np.degrees(diamond_min_angles(mesh, F, T))
    assert angles.shape == (len(mesh.diamonds),)
    assert np.all(angles > 0)
    # on a boundary edge (F_a, F_b, T): isosceles, base 1, height 1/6
    boundary = np.degrees(np.arctan((1 / 6) / (1 / 2)))
    assert angles[mesh.boundary] == pytest.approx(np.full(4, boundary))


def test_observer_sees_every_time_level_including_zero():
    quality = MeshQuality()
    simulate(*icosphere(1), 0.01, 5, save_every=0, observer=quality)
    df = quality.frame()
    assert df["n"].tolist() == list(range(6))
    np.testing.assert_allclose(df["t"], 0.01 * np.arange(6))
    assert (np.diff(df["volume"]) < 0).all()
