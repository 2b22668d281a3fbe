"""The experiments behind Figs. 3.1-3.8 of the paper, declared in one place.

An :class:`Experiment` is one figure: the runs it needs (:class:`Run`:
initial shape and its parameters, scheme, ``tau``, number of steps,
tangential setting) and the panels to draw (:class:`Shot`: which run,
which time level, zoom). ``EXPERIMENTS`` maps the figure name
(``"fig_3_2"``) to it; :func:`mcfbench.studies.figures.job` runs one
experiment and draws it (:mod:`mcfbench.studies.figures`).

What a figure shows, so that its PNG can be read alone:

* every panel label gives the time level ``n``, ``n_V`` (DDFV: F- plus
  T-vertices, the paper's count; the other schemes: the mesh vertices) and
  ``tau`` (:data:`LABEL`); Fig. 3.1 has no time step and says so instead
  of a ``tau``;
* a legend below the panels names the primal edges (blue), the diamond
  edges (red), the tracked cells and the detail region where drawn
  (:func:`mcfbench.presentation.render.legend_handles`);
* :class:`Track` (Fig. 3.4): a few diamond cells, chosen once, are filled
  in amber in every panel of their run, and the details follow them
  (``Zoom(at="tracked")``) with one half-width for all detail panels.

Choices not stated in the paper (it gives only ``n_V``, ``tau`` for
Figs. 3.2 and 3.5, and the time levels shown):

* shapes and their parameters: see :mod:`mcfbench.geometry.surfaces` (bumpy sphere
  with eight Gaussian bumps; cymling with flattening 0.4, 9 scallops of
  10 %; cylinder ``R = 1``, ``h = 0.55``, 24 x 8 twisted quads; hemisphere
  of radius 1 with 10 rings);
* ``tau = 0.0025`` everywhere (the paper's value for Figs. 3.2 and 3.5,
  assumed for the others);
* the cymling's flattening is chosen so that, as in the paper, ``n = 12``
  is the last level before the contracted diamond cells go wrong (a
  T-vertex leaves its triangle at ``n = 13``);
* Fig. 3.4 is seen from the viewpoint of Fig. 3.3; its tracked cells are
  the five diamond cells of the two triangles of the visible diamond with
  the smallest angle at ``n = 12`` (one of these triangles is the one whose
  T-vertex leaves it at ``n = 13``);
* with these choices the cylinder without elimination loses a T-vertex
  from its triangle between ``n = 580`` and ``n = 640`` (at ``n = 592``),
  as in Fig. 3.6.
"""

from dataclasses import asdict, dataclass, field

from mcfbench.running.schemes import get_scheme

TAU = 0.0025

#: default panel label: ``{n}`` time level shown, ``{n_V}`` number of
#: vertices (DDFV: F + T), ``{n_F}``, ``{n_T}``, ``{tau}``
LABEL = "n = {n}\nn_V = {n_V}, \u03c4 = {tau:g}"


@dataclass(frozen=True)
class Run:
    """One simulation.

    Attributes
    ----------
    key : str
        Name of the run inside its experiment.
    shape : str
        A name of :data:`mcfbench.geometry.surfaces.SURFACES`.
    params : dict
        Parameters of the shape generator.
    tau : float
    steps : int
    save_every : int
        Frames kept (every panel's time level must be a multiple).
    scheme : str
        A name of :data:`mcfbench.running.schemes.SCHEMES` (``ddfv-eliminate``: the
        elimination (3.6)).
    t_init : str
        T-vertex initialisation (Section 3), DDFV schemes only.
    label : str
        Short description for legends.
    """

    key: str
    shape: str
    params: dict = field(default_factory=dict)
    tau: float = TAU
    steps: int = 0
    save_every: int = 1
    scheme: str = "ddfv"
    t_init: str = "paper"
    label: str = ""

    def config(self):
        return asdict(self)


@dataclass(frozen=True)
class Zoom:
    """A detail of half-width ``half`` (in length units of the surface).

    ``at`` is a 3-D point; ``"worst"``: the visible element worst by the
    measure ``by`` (:func:`mcfbench.presentation.render.worst_element`: the diamond
    with the smallest angle, or the T-vertex with the smallest barycentric
    coordinate) at time level ``step`` (by default the panel's own),
    followed to the panel's time level; or ``"tracked"``: the centre of the
    experiment's tracked cells (:class:`Track`) at the panel's time level.
    """

    half: float
    at: object = "worst"
    step: int | None = None
    by: str = "angle"


@dataclass(frozen=True)
class Track:
    """Diamond cells of run ``run`` marked in every panel of that run.

    At time level ``step`` the visible element worst by ``by`` is taken
    (:func:`mcfbench.presentation.render.worst_element`): for ``"angle"`` the diamond
    with the smallest angle, and the cells tracked are the diamonds of its
    two triangles (:func:`mcfbench.presentation.render.tracked_cells`); for
    ``"barycentric"`` the three diamonds of the triangle whose T-vertex is
    nearest to leaving it. The same diamond indices are then filled in
    every panel of the run.
    """

    run: str
    step: int
    by: str = "angle"


@dataclass(frozen=True)
class Shot:
    """One panel: run ``run`` at time level ``step``.

    ``label`` is a template (:data:`LABEL`) with ``{n}`` for the time level
    shown, ``{n_V}``, ``{n_F}``, ``{n_T}`` and ``{tau}``. ``zoom`` shows
    a detail; ``box`` outlines, in a full view, the region of a detail
    shown in another panel (the :class:`Zoom` of that panel).
    """

    run: str
    step: int
    label: str = LABEL
    zoom: Zoom | None = None
    box: Zoom | None = None


@dataclass(frozen=True)
class Experiment:
    """A figure: runs, panels, view and caption.

    ``track`` marks the same diamond cells in every panel of its run
    (:class:`Track`).
    """

    name: str
    title: str
    caption: str
    runs: tuple
    shots: tuple
    view: tuple = (20.0, -60.0)
    rows: int = 1
    size: float = 2.6
    aspect: float = 1.0
    track: Track | None = None

    def run(self, key):
        for r in self.runs:
            if r.key == key:
                return r
        raise KeyError(f"experiment {self.name} has no run {key!r}")

    def config(self):
        config = {"name": self.name, "runs": [r.config() for r in self.runs],
                  "shots": [asdict(s) for s in self.shots], "view": list(self.view)}
        if self.track is not None:
            config["track"] = asdict(self.track)
        return config

    def describe(self):
        """The runs as a reStructuredText bullet list (for report captions)."""
        lines = []
        for r in self.runs:
            params = ", ".join(f"{k} = {v}" for k, v in r.params.items())
            scheme = get_scheme(r.scheme)
            what = f"{scheme.label} (``{scheme.name}``), shape ``{r.shape}`` ({params}), " \
                   f"tau = {r.tau:g}, {r.steps} steps"
            if scheme.extra_points:
                what += f", T-vertices ``{r.t_init}``"
            lines.append(f"- ``{r.key}``: {what}")
        steps = ", ".join(str(s.step) + (" (detail)" if s.zoom else "") for s in self.shots)
        lines.append(f"- panels at n = {steps}; view elevation {self.view[0]:g}, "
                     f"azimuth {self.view[1]:g} degrees")
        if self.track is not None:
            lines.append(f"- tracked diamond cells (amber) of run ``{self.track.run}``: those "
                         f"around the visible element worst by {self.track.by} at "
                         f"n = {self.track.step}")
        return "\n".join(lines)


def _shots(run, steps, **kw):
    return tuple(Shot(run, n, **kw) for n in steps)


_CYLINDER = dict(around=24, along=8, radius=1.0, half_height=0.55, diagonals="twisted")
_CYMLING = dict(level=3, flattening=0.4, lobes=9, wave=0.1)
_CYMLING_VIEW = (35.0, -60.0)    # Figs. 3.3, 3.4 and the cymling comparison
_BUMPY = dict(level=3, amplitude=0.25, width=0.2)
_RIM_ZOOM = Zoom(0.15, "tracked")
_CYL_ZOOM = Zoom(0.25, "worst", 640, by="barycentric")
_DETAIL = "n = {n} (detail)\nn_V = {n_V}, \u03c4 = {tau:g}"
_CYLINDER_RUN = "n_V = 600 (216 F-vertices, 384 T-vertices), tau = 0.0025"

EXPERIMENTS = {e.name: e for e in [
    Experiment(
        "fig_3_1", "Sphere discretisations for the DDFV method",
        "Discretisations of the unit sphere used by the DDFV method, from left to "
        "right n_V = 122, 482, 1922 and 7682 (icosphere levels 1 to 4; n_V counts the "
        "F-vertices and the T-vertices), the initial meshes n = 0 (no time step). Blue: "
        "the primal triangles (F-edges); red: the diamond mesh joining every F-vertex to "
        "the T-vertices of its triangles, initialised as in Section 3.",
        runs=tuple(Run(f"level{k}", "sphere", {"level": k}, steps=0,
                       label=f"level {k}, n_V = {30 * 4**k + 2}") for k in (1, 2, 3, 4)),
        shots=tuple(Shot(f"level{k}", 0, label=f"icosphere level {k}: n_V = {{n_V}}\n"
                         "n = {n} (initial mesh, no time step)") for k in (1, 2, 3, 4)),
        view=(20.0, -60.0), size=3.2),
    Experiment(
        "fig_3_2", "Bumpy sphere",
        "Mean curvature flow of a bumpy sphere with n_V = 1922 and tau = 0.0025, "
        "shown at time steps n = 0, 4, 12 and 32. The T-vertices follow the "
        "F-vertices; none escapes from its triangle.",
        runs=(Run("ddfv", "bumpy_sphere", _BUMPY, steps=32, save_every=4, label="DDFV"),),
        shots=_shots("ddfv", (0, 4, 12, 32))),
    Experiment(
        "fig_3_3", "Cymling-like shape",
        "Mean curvature flow of a cymling-like (pattypan squash) shape with "
        "n_V = 1922 and tau = 0.0025, at time steps n = 0, 4, 8 and 12. The rim, "
        "where the initial curvature is high, is where the diamond mesh deteriorates.",
        runs=(Run("ddfv", "cymling", _CYMLING, steps=12, save_every=1, label="DDFV"),),
        shots=_shots("ddfv", (0, 4, 8, 12)), view=_CYMLING_VIEW, aspect=0.7),
    Experiment(
        "fig_3_4", "Contraction of diamond cells (cymling, detail)",
        "Detail of the cymling-like shape of Fig. 3.3 (n_V = 1922, tau = 0.0025, seen "
        "from the same viewpoint) at its rim, the region of high initial curvature. "
        "Left: the whole shape at n = 12, the dashed square marking the detail; then "
        "the same diamond cells at n = 0, 8 and 12, all details at the same scale "
        "(half-width 0.15) and centred on the tracked cells. Highlighted in amber in "
        "every panel: the five diamond cells of the two triangles of the most "
        "contracted diamond at n = 12 (the same cells in every panel). The cells "
        "contract; one step later (n = 13) the T-vertex of one of these triangles "
        "leaves it.",
        runs=(Run("ddfv", "cymling", _CYMLING, steps=13, save_every=1, label="DDFV"),),
        shots=(Shot("ddfv", 12, "n = {n} (whole shape)\nn_V = {n_V}, \u03c4 = {tau:g}",
                    box=_RIM_ZOOM),
               Shot("ddfv", 0, _DETAIL, zoom=_RIM_ZOOM),
               Shot("ddfv", 8, _DETAIL, zoom=_RIM_ZOOM),
               Shot("ddfv", 12, _DETAIL, zoom=_RIM_ZOOM)),
        view=_CYMLING_VIEW, aspect=0.7, track=Track("ddfv", 12, "angle")),
    Experiment(
        "fig_3_5", "Cylinder to catenoid",
        "Mean curvature flow of an open cylinder (radius 1, height 1.1) with both "
        "boundary circles fixed, n_V = 600, tau = 0.0025, diamond mesh shown, at time "
        "steps n = 0, 40, 100 and 200: the surface approaches the catenoid.",
        runs=(Run("ddfv", "cylinder", _CYLINDER, steps=200, save_every=20, label="DDFV"),),
        shots=_shots("ddfv", (0, 40, 100, 200)), view=(12.0, -60.0), aspect=0.8),
    Experiment(
        "fig_3_6", "Degeneration of the diamond mesh (cylinder)",
        f"Continuation of the cylinder of Fig. 3.5 ({_CYLINDER_RUN}) without tangential "
        "control. At n = 580 the T-vertices in the second row of triangles from each "
        "boundary circle have drifted towards the edges of their triangles; by n = 640 "
        "they have left them and the diamond mesh folds over (dark cells near the rims). "
        "Right: the folded region at n = 640 "
        "in detail. The run record gives the first step at which a T-vertex left its "
        "triangle.",
        runs=(Run("ddfv", "cylinder", _CYLINDER, steps=640, save_every=20,
                  label="DDFV, no tangential control"),),
        shots=(Shot("ddfv", 580), Shot("ddfv", 640, box=_CYL_ZOOM),
               Shot("ddfv", 640, _DETAIL, zoom=_CYL_ZOOM)),
        view=(12.0, -60.0), aspect=0.8),
    Experiment(
        "fig_3_7", "Cylinder with tangential velocity eliminated",
        f"The cylinder of Fig. 3.5 ({_CYLINDER_RUN}) computed with the tangential "
        "velocity eliminated (3.6), at time steps n = 0, 100, 200 and 640: the "
        "T-vertices stay inside their triangles and the diamond mesh does not degenerate.",
        runs=(Run("ddfv", "cylinder", _CYLINDER, steps=640, save_every=20,
                  scheme="ddfv-eliminate", label="DDFV, elimination (3.6)"),),
        shots=_shots("ddfv", (0, 100, 200, 640)), view=(12.0, -60.0), aspect=0.8),
    Experiment(
        "fig_3_8", "Hemisphere with fixed equator",
        "Mean curvature flow of a hemisphere whose equator is held fixed, with the "
        "tangential velocity eliminated (3.6), n_V = 931, tau = 0.0025, at time steps "
        "n = 0, 40, 80 and 600: the surface flattens to the disk spanned by the equator.",
        runs=(Run("ddfv", "hemisphere", {"rings": 10}, steps=600, save_every=40,
                  scheme="ddfv-eliminate", label="DDFV, elimination (3.6)"),),
        shots=_shots("ddfv", (0, 40, 80, 600)), view=(25.0, -60.0), aspect=0.75),
    Experiment(
        "fig_3_6_cotan", "Cylinder: DDFV and the cotangent scheme",
        "The cylinder of Figs. 3.5-3.6 (tau = 0.0025; n_V = 600 for DDFV; the cotangent "
        "scheme has the n_V = 216 F-vertices only) at n = 200, 580 and 640: top, DDFV "
        "without tangential control; bottom, the cotangent scheme (baselines/cotan.py) "
        "with the same fixed boundary circles. Both approach the catenoid; the cotangent "
        "mesh has no T-vertices to drift and stays regular.",
        runs=(Run("ddfv", "cylinder", _CYLINDER, steps=640, save_every=20, label="DDFV"),
              Run("cotan", "cylinder", _CYLINDER, steps=640, save_every=20,
                  scheme="cotan", label="cotangent")),
        shots=(_shots("ddfv", (200, 580, 640), label="DDFV, " + LABEL)
               + _shots("cotan", (200, 580, 640), label="cotangent, " + LABEL)),
        rows=2, view=(12.0, -60.0), aspect=0.8),
    Experiment(
        "fig_3_4_cotan", "Cymling: DDFV and the cotangent scheme",
        "The cymling-like shape of Fig. 3.3 (tau = 0.0025) at n = 0, 8 and 12: top, "
        "DDFV (n_V = 1922); bottom, the cotangent scheme (baselines/cotan.py) on the same "
        "n_V = 642 F-vertices. The mesh contracts at the rim in both.",
        runs=(Run("ddfv", "cymling", _CYMLING, steps=12, save_every=1, label="DDFV"),
              Run("cotan", "cymling", _CYMLING, steps=12, save_every=1,
                  scheme="cotan", label="cotangent")),
        shots=(_shots("ddfv", (0, 8, 12), label="DDFV, " + LABEL)
               + _shots("cotan", (0, 8, 12), label="cotangent, " + LABEL)),
        rows=2, view=_CYMLING_VIEW, aspect=0.7),
]}
"""Figure name -> :class:`Experiment`."""

PAPER_FIGURES = tuple(f"fig_3_{k}" for k in range(1, 9))


def validate(experiment):
    """Check that the experiment can be drawn from what its runs keep.

    Every panel's time level (and those of its zoom, box and of the
    tracked cells) is computed and kept as a frame, runs and schemes
    exist, a ``"tracked"`` zoom has a :class:`Track` of its run, and every
    label template has only the fields of :data:`LABEL`.

    Raises
    ------
    ValueError
    """
    from mcfbench.presentation.render import WORST_MEASURES

    def kept(run, step, what):
        if step > run.steps or (step % run.save_every and step != run.steps):
            raise ValueError(f"{experiment.name}: time level {step} of run {run.key} "
                             f"({what}) is not kept (steps {run.steps}, "
                             f"save_every {run.save_every})")

    for run in experiment.runs:
        get_scheme(run.scheme)
    track = experiment.track
    if track is not None:
        kept(experiment.run(track.run), track.step, "tracked cells")
        if track.by not in WORST_MEASURES:
            raise ValueError(f"{experiment.name}: unknown track measure {track.by!r}")
    for shot in experiment.shots:
        run = experiment.run(shot.run)
        kept(run, shot.step, "panel")
        for zoom in (shot.zoom, shot.box):
            if zoom is None:
                continue
            if zoom.step is not None:
                kept(run, zoom.step, "zoom")
            if zoom.at == "tracked" and (track is None or track.run != shot.run):
                raise ValueError(f"{experiment.name}: a zoom at the tracked cells needs a "
                                 f"Track of run {shot.run}")
        try:
            shot.label.format(n=0, n_V=0, n_F=0, n_T=0, tau=1.0)
        except (KeyError, IndexError, ValueError) as err:
            raise ValueError(f"{experiment.name}: bad panel label {shot.label!r} "
                             f"({err!r}); fields n, n_V, n_F, n_T, tau") from None
