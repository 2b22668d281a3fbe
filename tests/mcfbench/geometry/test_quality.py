"""Mesh-quality diagnostics (mcfbench/geometry/quality.py)."""

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from baselines.cotan import CotanFlow
from ddfv import Flow
from ddfv.topology import diamond_mesh
from mcfbench.geometry.quality import (
    COLUMNS,
    DIAMOND_COLUMNS,
    MeshQuality,
    describe_violation,
    diamond_min_angles,
    first_violation,
    mesh_quality,
    primal_quality,
    vertex_quality,
)
from mcfbench.geometry.shapes import cylinder
from mcfbench.geometry.spheres import icosphere
from mcfbench.presentation.quality_plots import plot_quality
from mcfbench.running.driver import simulate


@pytest.fixture(scope="module")
def sphere():
    """Level-2 icosphere with the paper's T-vertices."""
    flow = Flow(*icosphere(2), 0.01)
    return diamond_mesh(flow.faces), flow.F, flow.T


def test_paper_initialisation_puts_t_vertices_near_the_barycentres(sphere):
    q = mesh_quality(*sphere)
    assert 0.32 < q["t_bary_min"] <= 1 / 3 + 1e-12
    assert q["t_bary_median"] == pytest.approx(1 / 3, abs=2e-3)
    assert 0.5 < q["diamond_area_min_rel"] <= 1.0
    # the triangles (F_a, F_b, T) of a near-equilateral mesh: angles near 30 degrees
    assert 20.0 < q["angle_min_deg"] <= 30.0 + 1e-9
    # the primal icosphere: near-equilateral triangles, none folded
    assert q["family"] == "ddfv"
    assert 50.0 < q["min_angle"] <= 60.0
    assert 0.8 < q["primal_area_min_rel"] <= 1.0 and q["flipped"] == 0


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
    simulate(Flow(F, mesh.faces, 0.01, T0=T), 3, observers=[quality])
    df = quality.frame()
    assert list(df.columns) == list(COLUMNS)
    assert df["n"].tolist() == [0, 1, 2, 3]
    assert (df["family"] == "ddfv").all()
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
    simulate(Flow(*icosphere(1), 0.01), 5, save_every=0, observers=[quality])
    df = quality.frame()
    assert df["n"].tolist() == list(range(6))
    np.testing.assert_allclose(df["t"], 0.01 * np.arange(6))
    assert (np.diff(df["volume"]) < 0).all()


def test_primal_quality_of_a_flat_square():
    # four right isosceles triangles around the centre: 45 degrees, equal areas
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0.0]])
    faces = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    q = primal_quality(V, faces)
    assert q["min_angle"] == pytest.approx(45.0)
    assert q["primal_area_min_rel"] == pytest.approx(1.0)
    assert q["flipped"] == 0
    V[4] = [0.9, 0.5, 0.0]          # the centre moved right: triangle 1 shrinks
    q = primal_quality(V, faces)
    assert q["worst_triangle"] == 1
    assert q["primal_area_min_rel"] == pytest.approx(0.05 / 0.25)  # base 1, height 0.1; mean 1/4


def test_cotangent_run_has_primal_rows_and_empty_diamond_columns():
    V, faces = cylinder(12, 4, 1.0, 0.55, "twisted")
    quality = MeshQuality()
    simulate(CotanFlow(V, faces, 0.0025), 4, observers=[quality])
    df = quality.frame()
    assert list(df.columns) == list(COLUMNS) and len(df) == 5
    assert (df["family"] == "vertex").all()
    assert df[list(DIAMOND_COLUMNS)].isna().all().all()
    assert (df["min_angle"] > 20).all() and (df["flipped"] == 0).all()
    # the area of the triangle mesh decreases under the flow (boundary fixed)
    assert df["area"].iloc[0] == pytest.approx(vertex_quality(V, faces)["area"])
    assert (np.diff(df["area"]) < 0).all()
    # the empty diamond monitors are not a violation of a vertex run
    assert first_violation(df) is None and describe_violation(df) == ""
    bad = df.copy()
    bad.loc[3, ["primal_area_min_rel", "worst_triangle"]] = [1e-12, 7]
    assert first_violation(bad) == 3
    assert "triangle 7 collapsed" in describe_violation(bad)
    bad = df.copy()
    bad.loc[2, "flipped"] = 2
    assert first_violation(bad) == 2 and "2 triangle(s) folded over" in describe_violation(bad)


def test_indices_are_integers_in_the_csv():
    quality = MeshQuality()
    simulate(Flow(*icosphere(1), 0.01), 1, observers=[quality])
    text = quality.frame().to_csv(index=False)
    header, first = text.splitlines()[:2]
    row = dict(zip(header.split(","), first.split(",")))
    assert row["worst_t"].isdigit() and row["worst_triangle"].isdigit()
    assert row["family"] == "ddfv"


def _series(n_steps, family, **values):
    n = np.arange(n_steps)
    df = pd.DataFrame({"n": n, "t": 0.01 * n, "family": family})
    for key in COLUMNS:
        if key not in df:
            df[key] = values.get(key, np.full(n_steps, np.nan if (
                family == "vertex" and key in DIAMOND_COLUMNS) else 0.5))
    df["area"] = 1.0 - 0.01 * n
    df["flipped"] = 0
    return df[list(COLUMNS)]


def test_plot_of_a_run_far_outside_shows_every_curve():
    """The T-barycentric axis goes symlog and down to the smallest value."""
    n = 50
    ddfv = _series(n, "ddfv", t_bary_min=np.linspace(1 / 3, -2.5, n))
    cotan = _series(n, "vertex")
    fig = plot_quality({"DDFV": ddfv, "cotangent": cotan}, title="t", marks=[10, 40])
    ax_b = fig.axes[0]
    assert ax_b.get_yscale() == "symlog"
    low, high = ax_b.get_ylim()
    assert low < -2.5 and high > 1 / 3
    texts = [t.get_text() for t in ax_b.texts]
    assert any(t.startswith("0: a T-vertex leaves its triangle") for t in texts)
    # both runs in the angle, area and surface-area panels (DDFV twice: diamond, primal)
    ax_g, ax_a, ax_v = fig.axes[1:4]
    assert len(ax_g.get_lines()) >= 3 and len(ax_v.get_lines()) >= 2
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels[0].startswith("DDFV: first violation at n = ")
    assert labels[1] == "cotangent: no violation"
    assert "cotangent (primal mesh)" in fig._suptitle.get_text()
    plt.close(fig)


def test_plot_without_time_steps_is_a_bar_chart_that_says_so():
    rows = {f"level {k}": _series(1, "ddfv", t_bary_min=[0.33]) for k in (1, 2, 3)}
    fig = plot_quality(rows, title="fig_3_1: spheres")
    title = fig._suptitle.get_text()
    assert title.startswith("fig_3_1: spheres\n") and "no time series" in title
    assert len(fig.axes) == 3
    assert [t.get_text() for t in fig.axes[0].get_yticklabels()] == list(rows)
    # one bar per mesh in the barycentric panel, two (diamond, primal) in the others
    bars = [len(ax.patches) for ax in fig.axes]
    assert bars == [3, 6, 6]
    assert any(t.get_text().strip() == "0.3300" for t in fig.axes[0].texts)
    plt.close(fig)
