"""One figure of Figs. 3.1-3.8: run its experiment and draw it.

The experiments (runs, panels, views, captions) are declared in
:mod:`mcfbench.studies.figures.experiments` (``EXPERIMENTS``). The study
protocol (``workflow/rules/figures.smk`` calls it):

* :func:`job`: one figure: its runs (:func:`run_experiment`, each
  :func:`mcfbench.running.run.framed_run` with every kept frame, the mesh
  quality monitor and ``on_defect="record"``), the figure, the frames, the
  per-step diagnostics and the record, all written atomically.

Drawing: :func:`experiment_panels` and :func:`draw_experiment`
(:mod:`mcfbench.presentation.render`).
"""

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mcfbench.geometry.quality import MeshQuality, describe_violation, first_violation
from mcfbench.geometry.surfaces import make_surface
from mcfbench.running.problems import Problem
from mcfbench.running.run import framed_run
from mcfbench.running.schemes import get_scheme
from mcfbench.running.solver import Solver
from mcfbench.storage.frames import surface_points
from mcfbench.storage.records import RunResult
from mcfbench.studies.figures.experiments import EXPERIMENTS, Run, validate


@dataclass
class FigureRun:
    """One :class:`~mcfbench.studies.figures.experiments.Run` done: its result, its
    frames (the layout of :mod:`mcfbench.storage.frames`) and its mesh quality
    (``None`` when the scheme refused the surface)."""

    run: Run
    result: RunResult
    frames: dict
    quality: object = None  # pandas.DataFrame of mcfbench.geometry.quality.MeshQuality

    @property
    def vertices(self):
        """(frames, n, 3): the surface mesh's vertices (DDFV: the F-vertices)."""
        return surface_points(self.frames)[0]

    @property
    def extra_points(self):
        """(frames, n_t, 3): DDFV's T-vertices; None for the vertex schemes."""
        return surface_points(self.frames)[1]

    @property
    def steps(self):
        return self.frames["steps"]

    @property
    def faces(self):
        return self.frames["faces"]

    @property
    def status(self):
        return self.result.status

    @property
    def message(self):
        return self.result.message

    @property
    def failed_step(self):
        """Time level of the first defect or breakdown, ``-1`` when ``ok``."""
        r = self.result
        return -1 if r.status == "ok" else round(r.t_failed / r.tau)

    def frame(self, step):
        """Index of the last kept frame at or before ``step``."""
        return int(np.searchsorted(self.steps, step, side="right") - 1)

    def record(self):
        """JSON-serialisable summary."""
        violation = None if self.quality is None else first_violation(self.quality)
        return {
            "run": self.run.config(),
            "status": self.status,
            "message": self.message,
            "failed_step": int(self.failed_step),
            "last_step": int(self.steps[-1]),
            "frames": [int(s) for s in self.steps],
            "iterations": int(self.result.iterations),
            "wall_seconds": round(self.result.wall_seconds, 3),
            "first_violation": violation,
            "violation": "" if self.quality is None else describe_violation(self.quality),
        }


def figure_run(run):
    """One :class:`~mcfbench.studies.figures.experiments.Run` through
    :func:`mcfbench.running.run.framed_run`: the shape's mesh, ``run.steps`` steps
    of ``run.tau``, every ``run.save_every``-th frame kept.

    The run goes on past an invalid state (``on_defect="record"``: the
    figures show what happens after a T-vertex leaves its triangle), and
    its status says what went wrong first; a breakdown of the solver ends
    it, keeping the frames computed before. The mesh quality of every time
    level is recorded (:class:`mcfbench.geometry.quality.MeshQuality`: diamond and
    primal monitors for DDFV, primal ones for the other schemes). A scheme that
    refuses the surface gives ``status = "unsupported"`` with the initial surface
    as its frames.

    Returns
    -------
    FigureRun
    """
    scheme = get_scheme(run.scheme)
    options = {"t_init": run.t_init} if scheme.extra_points else {}
    quality = MeshQuality()   # diamond and primal monitors (DDFV), primal (the others)
    result, frames = framed_run(scheme, Problem.user_mesh(run.shape, run.steps), 0,
                                solver=Solver(), mesh=make_surface(run.shape, **run.params),
                                tau=run.tau, save_every=run.save_every, on_defect="record",
                                observers=[quality], **options)
    return FigureRun(run, result, frames,
                     None if result.status == "unsupported" else quality.frame())


def run_experiment(experiment):
    """:func:`figure_run` for every run of the experiment: ``{key: FigureRun}``."""
    validate(experiment)
    return {run.key: figure_run(run) for run in experiment.runs}


def experiment_status(results):
    """Overall status: ``"ok"`` or the first run's non-ok status."""
    for result in results.values():
        if result.status != "ok":
            return result.status
    return "ok"


def tracked(experiment, results):
    """The tracked diamond cells of the experiment (:class:`Track`).

    Returns
    -------
    dict
        ``{run key: (k,) int array}`` of diamond indices (empty without a
        track or when the run has no frame at the track's time level).
    """
    from mcfbench.presentation.render import tracked_cells, worst_element

    track = experiment.track
    if track is None:
        return {}
    result = results[track.run]
    j = result.frame(track.step)
    if j < 0 or int(result.steps[j]) != track.step:
        return {}
    extra = None if result.extra_points is None else result.extra_points[j]
    k = worst_element(result.vertices[j], extra, result.faces, experiment.view, track.by)
    if track.by == "angle":
        cells = tracked_cells(result.faces, k, result.vertices.shape[1])
    else:
        from ddfv.topology import diamond_mesh

        cells = np.unique(diamond_mesh(result.faces, result.vertices.shape[1]).halfedges[k])
    return {track.run: cells}


def experiment_panels(experiment, results):
    """The :class:`mcfbench.presentation.render.Panel` of every shot, in order.

    A panel whose time level was not reached shows the last frame of its
    run, labelled with the level shown and a note. Panels of a tracked run
    have the tracked cells as ``highlight``; a zoom ``"tracked"`` is centred
    on their centre in the panel's own frame, with the half-width of its
    :class:`Zoom` (one for all panels that share it).
    """
    from mcfbench.presentation.render import (
        Panel,
        cells_centre,
        element_centre,
        worst_element,
    )

    cells = tracked(experiment, results)

    def zoom_of(spec, result, i, run):
        """Centre and half-width of a zoom in frame ``i`` of ``result``."""
        if spec is None:
            return None
        extra = result.extra_points
        if not isinstance(spec.at, str):
            return np.asarray(spec.at, dtype=float), spec.half
        if spec.at == "tracked":
            if run not in cells:
                return None
            return cells_centre(result.vertices[i], None if extra is None else extra[i],
                                result.faces, cells[run]), spec.half
        j = result.frame(spec.step) if spec.step is not None else i
        k = worst_element(result.vertices[j], None if extra is None else extra[j],
                          result.faces, experiment.view, spec.by)
        centre = element_centre(result.vertices[i], None if extra is None else extra[i],
                                result.faces, k, spec.by)
        return centre, spec.half

    panels = []
    for shot in experiment.shots:
        result = results[shot.run]
        i = result.frame(shot.step)
        reached = int(result.steps[i])
        n_f = result.vertices.shape[1]
        n_t = 0 if result.extra_points is None else result.extra_points.shape[1]
        label = shot.label.format(n=reached, n_V=n_f + n_t, n_F=n_f, n_T=n_t,
                                  tau=result.run.tau)
        note = ""
        if result.status == "unsupported":
            name = result.run.label or result.run.scheme
            note = f"{name}: not computed\n{_short(result.message)}"
        elif reached != shot.step:
            note = f"n = {shot.step} not reached:\n{_short(result.message or result.status)}"
        extra = None if result.extra_points is None else result.extra_points[i]
        panels.append(Panel(result.vertices[i], extra, result.faces, label=label,
                            zoom=zoom_of(shot.zoom, result, i, shot.run),
                            zoom_box=zoom_of(shot.box, result, i, shot.run),
                            note=note, highlight=cells.get(shot.run)))
    return panels


def draw_experiment(experiment, results):
    """The figure of an experiment from its runs' frames.

    The panels of :func:`experiment_panels` in a grid, titled with the
    experiment's name and title, with a legend of what is drawn.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from mcfbench.presentation.render import panel_row

    return panel_row(experiment_panels(experiment, results), view=experiment.view,
                     rows=experiment.rows, size=experiment.size, aspect=experiment.aspect,
                     title=f"{experiment.name}: {experiment.title}")


def _short(text, width=34):
    import textwrap

    return "\n".join(textwrap.wrap(text, width)[:3])


# ---------------------------------------------------------------- the job


def frames_file(folder, key):
    """The frames file of run ``key`` in a figure's frames folder."""
    return Path(folder) / f"{key}.npz"


def job(name, outputs, log):
    """Run the experiment of one figure (:data:`EXPERIMENTS`) and draw it.

    Writes the figure (PNG + PDF), the kept frames of every run (one frames
    file per run in the folder ``outputs["frames"]``,
    :func:`mcfbench.storage.frames.save_frames`), the per-step diagnostics of
    the runs (CSV with a ``run`` column, and a plot) and a JSON record (status
    per run, first violation, timings, provenance). A run that breaks down
    keeps its frames and the figure is drawn from them with a note.

    Returns
    -------
    str
        The figure's status (:func:`experiment_status`).
    """
    import pandas as pd

    from mcfbench.geometry.quality import COLUMNS
    from mcfbench.presentation.quality_plots import plot_quality
    from mcfbench.presentation.render import DPI, rasterize_meshes
    from mcfbench.presentation.tables import csv
    from mcfbench.storage.atomic import json_text, write_files
    from mcfbench.storage.frames import save_frames
    from mcfbench.storage.provenance import provenance

    experiment = EXPERIMENTS[name]
    wall = time.perf_counter()
    results = run_experiment(experiment)
    compute = time.perf_counter() - wall
    quality = {key: r for key, r in results.items() if r.quality is not None}
    frames = [r.quality.assign(run=key) for key, r in quality.items()]
    table = pd.concat(frames, ignore_index=True) if frames else \
        pd.DataFrame(columns=["run", *COLUMNS])
    plot = plot_quality({r.run.label or key: r.quality for key, r in quality.items()},
                        title=f"{experiment.name}: {experiment.title}",
                        marks=sorted({s.step for s in experiment.shots}))
    draw = time.perf_counter()
    figure = draw_experiment(experiment, results)
    draw = time.perf_counter() - draw
    rasterize_meshes(figure)
    status = experiment_status(results)
    record = {
        "experiment": experiment.name, "title": experiment.title, "status": status,
        "first_violation": {key: r.record()["first_violation"] for key, r in quality.items()},
        "runs": {key: r.record() for key, r in results.items()},
        "seconds": {"compute": round(compute, 3), "draw": round(draw, 3),
                    "total": round(time.perf_counter() - wall, 3)},
        "outputs": {k: str(v) for k, v in outputs.items()},
        "provenance": provenance(experiment.config()),
    }
    for key, r in results.items():
        save_frames(frames_file(outputs["frames"], key), r.frames)
    write_files({outputs["csv"]: csv(table[["run", *COLUMNS]]),
                 outputs["plot"]: (plot, {"dpi": DPI}), outputs["png"]: (figure, {"dpi": DPI}),
                 outputs["pdf"]: (figure, {"dpi": 2 * DPI}),
                 outputs["record"]: json_text(record)})
    for key, r in results.items():
        line = f"{experiment.name}/{key}: {r.status}, n = {int(r.steps[-1])}"
        line += f" ({r.message})" if r.message else ""
        violation = r.record()["violation"]
        line += f"; first violation at {violation}" if violation else ""
        (log.warning if r.status != "ok" else log.info)("%s", line)
    log.info("%s: %s; compute %.1f s, draw %.1f s", experiment.name, status, compute, draw)
    return status
