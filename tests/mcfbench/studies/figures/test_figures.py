"""The experiments of Figs. 3.1-3.8 (mcfbench/studies/figures/experiments.py) and their
study (mcfbench/studies/figures/job.py): definitions, tracked cells, panels, the figure job's
frames files and the diagnostics of their runs."""

import dataclasses
import logging
import re

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
import pytest

from mcfbench.geometry.surfaces import make_surface
from mcfbench.presentation.render import cells_centre, cells_points, project
from mcfbench.running.schemes import SCHEMES, get_scheme
from mcfbench.studies.figures import figure_outputs
from mcfbench.studies.figures.experiments import (
    Experiment,
    EXPERIMENTS,
    LABEL,
    PAPER_FIGURES,
    Run,
    Shot,
    Track,
    validate,
    Zoom,
)
from mcfbench.studies.figures.job import (
    draw_experiment,
    experiment_panels,
    job,
    run_experiment,
    tracked,
)


def n_vertices(run):
    """The paper's n_V of a run: F- plus T-vertices for DDFV, the vertices otherwise."""
    V, faces = make_surface(run.shape, **run.params)
    return len(V) + (len(faces) if get_scheme(run.scheme).extra_points else 0)


@pytest.fixture(scope="module")
def fig_3_4():
    experiment = EXPERIMENTS["fig_3_4"]
    return experiment, run_experiment(experiment)


@pytest.fixture(scope="module")
def fig_3_4_panels(fig_3_4):
    return experiment_panels(*fig_3_4)


@pytest.mark.parametrize("name", list(EXPERIMENTS))
def test_every_experiment_validates_and_uses_registry_schemes(name):
    experiment = EXPERIMENTS[name]
    validate(experiment)
    for run in experiment.runs:
        assert run.scheme in SCHEMES
    for shot in experiment.shots:
        run = experiment.run(shot.run)
        assert shot.step <= run.steps
        assert shot.step % run.save_every == 0 or shot.step == run.steps


def test_the_paper_figures_and_the_comparisons_are_defined():
    assert PAPER_FIGURES == tuple(f"fig_3_{k}" for k in range(1, 9))
    assert set(PAPER_FIGURES) < set(EXPERIMENTS)
    assert {"fig_3_4_cotan", "fig_3_6_cotan"} < set(EXPERIMENTS)


@pytest.mark.parametrize("name", list(EXPERIMENTS))
def test_caption_mentions_what_the_figure_shows(name):
    experiment = EXPERIMENTS[name]
    caption = experiment.caption
    numbers = set(re.findall(r"\d+", caption))
    for shot in experiment.shots:                       # every time level shown
        assert str(shot.step) in numbers, f"n = {shot.step} missing from the caption"
    for run in experiment.runs:                         # the true size of every run
        assert f"n_V = {n_vertices(run)}" in caption or \
            re.search(rf"n_V = [\d, and]*\b{n_vertices(run)}\b", caption)
        if run.steps:
            assert f"tau = {run.tau:g}" in caption
    if any(SCHEMES[r.scheme].family == "vertex" for r in experiment.runs):
        assert "cotangent" in caption
    if any(r.scheme == "ddfv-eliminate" for r in experiment.runs):
        assert "(3.6)" in caption
    if experiment.track is not None:
        assert "same diamond cells" in caption and "amber" in caption
    if any(s.zoom for s in experiment.shots):
        assert "detail" in caption.lower()


def test_no_time_step_figure_says_so_instead_of_tau():
    experiment = EXPERIMENTS["fig_3_1"]
    assert all(r.steps == 0 for r in experiment.runs)
    assert "no time step" in experiment.caption
    for shot in experiment.shots:
        label = shot.label.format(n=0, n_V=122, n_F=42, n_T=80, tau=0.0025)
        assert "n_V = 122" in label and "n = 0" in label and "no time step" in label


def test_every_label_of_an_evolution_gives_n_nv_and_tau():
    for experiment in EXPERIMENTS.values():
        if all(r.steps == 0 for r in experiment.runs):
            continue
        for shot in experiment.shots:
            label = shot.label.format(n=7, n_V=600, n_F=216, n_T=384, tau=0.0025)
            assert "n = 7" in label and "n_V = 600" in label and "\u03c4 = 0.0025" in label


def test_validate_rejects_levels_not_kept_and_tracks_missing():
    run = Run("a", "sphere", {"level": 1}, steps=10, save_every=5)
    good = Experiment("x", "t", "c", (run,), (Shot("a", 5),))
    validate(good)
    with pytest.raises(ValueError, match="time level 3 of run a"):
        validate(dataclasses.replace(good, shots=(Shot("a", 3),)))
    with pytest.raises(ValueError, match="needs a Track"):
        validate(dataclasses.replace(good, shots=(Shot("a", 5, zoom=Zoom(0.1, "tracked")),)))
    with pytest.raises(ValueError, match="tracked cells"):
        validate(dataclasses.replace(good, track=Track("a", 7)))
    with pytest.raises(ValueError, match="bad panel label"):
        validate(dataclasses.replace(good, shots=(Shot("a", 5, label="{step}"),)))
    with pytest.raises(ValueError, match="unknown scheme"):
        validate(dataclasses.replace(good, runs=(dataclasses.replace(run, scheme="nope"),)))


def test_fig_3_4_has_the_viewpoint_of_fig_3_3():
    assert EXPERIMENTS["fig_3_4"].view == EXPERIMENTS["fig_3_3"].view
    assert EXPERIMENTS["fig_3_4"].aspect == EXPERIMENTS["fig_3_3"].aspect
    assert EXPERIMENTS["fig_3_4_cotan"].view == EXPERIMENTS["fig_3_3"].view


def test_fig_3_4_tracks_the_same_cells_in_every_panel(fig_3_4, fig_3_4_panels):
    experiment, results = fig_3_4
    cells = tracked(experiment, results)["ddfv"]
    assert len(cells) == 5                               # the diamonds of two triangles
    assert len(fig_3_4_panels) == len(experiment.shots) == 4
    for panel in fig_3_4_panels:
        np.testing.assert_array_equal(panel.highlight, cells)
    # as the caption says: the T-vertex of one of their triangles leaves it at n = 13
    result = results["ddfv"]
    assert result.status == "t_escaped" and result.failed_step == 13
    from ddfv.geometry import t_barycentric
    from ddfv.topology import diamond_mesh

    mesh = diamond_mesh(result.faces)
    triangles = np.unique(mesh.diamonds[cells, 2:])
    bary = t_barycentric(result.vertices[13], result.extra_points[13], result.faces).min(axis=1)
    assert bary[triangles].min() < 0 <= t_barycentric(
        result.vertices[12], result.extra_points[12], result.faces).min()


def test_fig_3_4_details_share_one_half_width_and_follow_the_cells(fig_3_4, fig_3_4_panels):
    experiment, results = fig_3_4
    result = results["ddfv"]
    details = [(s, p) for s, p in zip(experiment.shots, fig_3_4_panels) if p.zoom is not None]
    assert [s.step for s, _ in details] == [0, 8, 12]
    halves = {p.zoom[1] for _, p in details}
    assert halves == {0.15}                              # one scale for every detail
    extents = []
    for shot, panel in details:
        i = result.frame(shot.step)
        F, T = result.vertices[i], result.extra_points[i]
        centre = cells_centre(F, T, result.faces, panel.highlight)
        np.testing.assert_allclose(panel.zoom[0], centre)
        # every corner of the tracked cells lies inside the detail
        xy = project(cells_points(F, T, result.faces, panel.highlight), experiment.view)[0]
        c = project(centre[None], experiment.view)[0][0]
        assert (np.abs(xy[:, 0] - c[0]) < 0.15).all()
        assert (np.abs(xy[:, 1] - c[1]) < 0.15 * experiment.aspect).all()
        extents.append(np.ptp(xy, axis=0).max())
    # the cells contract: at n = 12 less than half their size at n = 0
    assert extents[2] < 0.5 * extents[0] and extents[1] < extents[0]
    # the overview outlines the region of the n = 12 detail
    overview = fig_3_4_panels[0]
    assert overview.zoom is None and experiment.shots[0].step == 12
    np.testing.assert_allclose(overview.zoom_box[0], details[-1][1].zoom[0])
    assert overview.zoom_box[1] == 0.15


def test_fig_3_4_labels_and_legend(fig_3_4, fig_3_4_panels):
    labels = [p.label for p in fig_3_4_panels]
    assert labels[1] == "n = 0 (detail)\nn_V = 1922, \u03c4 = 0.0025"
    assert labels[0].startswith("n = 12 (whole shape)\n")
    fig = draw_experiment(*fig_3_4)
    (legend,) = fig.legends
    texts = [t.get_text() for t in legend.get_texts()]
    assert [t.split()[0] for t in texts] == ["primal", "diamond", "tracked", "region"]
    assert fig._suptitle.get_text().startswith("fig_3_4: ")
    plt.close(fig)


def test_default_label_has_the_time_level_size_and_step():
    assert LABEL.format(n=4, n_V=1922, n_F=642, n_T=1280, tau=0.0025) == \
        "n = 4\nn_V = 1922, \u03c4 = 0.0025"


@pytest.fixture(scope="module")
def small_comparison(tmp_path_factory):
    """fig_3_6_cotan shortened to 4 steps, through the figure job."""
    base = EXPERIMENTS["fig_3_6_cotan"]
    runs = tuple(dataclasses.replace(r, steps=4, save_every=2) for r in base.runs)
    shots = tuple(dataclasses.replace(s, step=4) for s in base.shots[::3])
    experiment = dataclasses.replace(base, name="small_cotan", runs=runs, shots=shots)
    validate(experiment)
    out = tmp_path_factory.mktemp("figure")
    outputs = figure_outputs("small_cotan", out)
    EXPERIMENTS["small_cotan"] = experiment
    try:
        job("small_cotan", outputs, logging.getLogger("test"))
    finally:
        del EXPERIMENTS["small_cotan"]
    return experiment, outputs


def test_diagnostics_of_a_cotangent_run_contain_its_rows(small_comparison):
    experiment, outputs = small_comparison
    table = pd.read_csv(outputs["csv"])
    assert table.columns[0] == "run"
    cotan = table[table["run"] == "cotan"]
    ddfv = table[table["run"] == "ddfv"]
    assert cotan["n"].tolist() == [0, 1, 2, 3, 4] and ddfv["n"].tolist() == [0, 1, 2, 3, 4]
    assert (cotan["family"] == "vertex").all() and (ddfv["family"] == "ddfv").all()
    assert cotan["t_bary_min"].isna().all() and ddfv["t_bary_min"].notna().all()
    # the primal monitors of both: the twisted 24 x 8 cylinder, nothing folded
    for rows in (cotan, ddfv):
        assert (rows["min_angle"] > 30).all()
        assert (rows["primal_area_min_rel"] > 0.5).all()
        assert (rows["flipped"] == 0).all()
    # the flow decreases the area of the open cylinder, boundary fixed
    assert (np.diff(cotan["area"]) < 0).all()
    assert cotan["area"].iloc[0] == pytest.approx(4 * np.pi * 0.55, rel=0.02)  # 2 pi R h


def test_figure_job_writes_the_figure_and_a_two_run_diagnostics_plot(small_comparison):
    import json

    experiment, outputs = small_comparison
    assert outputs["png"].stat().st_size > 20_000 and outputs["plot"].stat().st_size > 20_000
    record = json.loads(outputs["record"].read_text())
    assert set(record["runs"]) == {"ddfv", "cotan"}
    assert record["first_violation"] == {"ddfv": None, "cotan": None}
    assert record["status"] == "ok"


def test_figure_job_keeps_one_frames_file_per_run_in_the_common_layout(small_comparison):
    from mcfbench.storage.frames import load_frames

    experiment, outputs = small_comparison
    ddfv = load_frames(outputs["frames"] / "ddfv.npz")
    cotan = load_frames(outputs["frames"] / "cotan.npz")
    # every second of 4 steps kept; the cylinder's 216 F-vertices and 384 triangles
    for frames in (ddfv, cotan):
        assert frames["steps"].tolist() == [0, 2, 4]
        np.testing.assert_allclose(frames["t"], [0, 0.005, 0.01])
        assert frames["faces"].shape == (384, 3)
    assert ddfv["vertices"].shape == (3, 216, 3) and ddfv["extra_points"].shape == (3, 384, 3)
    assert cotan["vertices"].shape == (3, 216, 3) and "extra_points" not in cotan
    # the boundary circles stay where they were
    np.testing.assert_array_equal(cotan["vertices"][-1][np.abs(cotan["vertices"][0][:, 2]) == 0.55],
                                  cotan["vertices"][0][np.abs(cotan["vertices"][0][:, 2]) == 0.55])
