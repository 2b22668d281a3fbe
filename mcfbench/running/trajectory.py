"""What a run computed: :class:`Trajectory`, the record that
:func:`mcfbench.running.driver.simulate` returns (frames, status, defects, events)."""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Trajectory:
    """What :func:`~mcfbench.running.driver.simulate` computed.

    Attributes
    ----------
    frames : dict of str -> (frames, ...) float arrays
        The arrays of :meth:`SchemeFlow.frame` stacked over the kept frames
        (``"vertices"``, and ``"extra_points"`` for DDFV). Frame 0 is the
        initial state, the last frame the last state computed.
    steps : (frames,) int array
        Time level of each frame.
    t : (frames,) float array
    faces : (m, 3) int array
        The initial mesh's (frame 0's).
    frame_faces : list of (m_k, 3) int arrays, or None
        Each frame's faces, for a run whose mesh changed (``remesh``): then
        ``frames`` holds the frames of :func:`mcfbench.storage.frames.changing_frames`
        (read them with :func:`~mcfbench.storage.frames.frame_mesh`); None when every
        frame has ``faces``.
    iterations : (n_steps,) int array
        Solver iterations of each completed step.
    status : str
        ``"ok"`` or the status of the first breakdown or defect
        (:data:`mcfbench.storage.statuses.STATUSES`).
    message : str
        Empty when ``status == "ok"``.
    failed_step : int
        Time level of the breakdown or first defect, ``-1`` when ``ok``.
    steps_done : int
        Time steps completed (in ``"record"`` mode possibly all of them
        although ``status`` is not ``ok``).
    defects : list of dict
        Every defect seen (``"record"`` mode: one per status, its first
        occurrence): ``status``, ``step``, ``time``, ``detail``.
    wall_seconds, cpu_seconds : float
        Time of the stepping, observers included.
    events : list of dict
        What happened to the surface without ending the run, and what ended it
        ``extinct``: one ``{"event": "extinct", "step", "time", "component",
        "kind", "area", "volume", "extinction_time"}`` per component that vanished
        round (:mod:`mcfbench.geometry.collapse`): ``time`` the state's, ``kind``
        ``"point"``, ``"circle"`` or ``"curve"``, ``area`` and ``volume`` the
        component's then,
        ``extinction_time`` the state's time plus the time the round component
        had left; the mesh strategies' (``simulate``'s ``remesh``): ``"remeshed"``
        (:meth:`~mcfbench.running.remeshing.Remesher.remeshed`), ``"rolled_back"`` and
        ``"rollback_refused"`` (:mod:`mcfbench.running.rollback`), ``"surgery"``
        (:meth:`~mcfbench.running.surgery.Surgeon.__call__`), ``"reextracted"`` and
        ``"refused"`` (:class:`~mcfbench.running.surgery.Reextractor`,
        ``surgery.refusal``).
    flow : mcfbench.running.flow.SchemeFlow
        The flow at the run's end: the one stepped, or the one rebuilt on the
        components that remained (``rebuild``).
    continue_with : callable or None
        For a run that ended with a solver failure (a ``solver_*`` status; not one
        turned into ``degenerated`` by a collapsed mesh), ``continue_with(solver,
        progress=False) -> Trajectory``: the same run continued from its last
        accepted state, the failed step tried again with ``solver`` (the flow,
        its integrator's past states, the checks and the observers exactly as
        the run left them; the failure is forgotten). The returned trajectory is
        the whole run's, from step 0, its times added up. The objects are those
        of this run, which is thereby used up: it can be continued once (the
        continued run, if its solver fails too, once more). None otherwise.
    """

    frames: dict
    steps: np.ndarray
    t: np.ndarray
    faces: np.ndarray
    iterations: np.ndarray
    frame_faces: list | None = None
    status: str = "ok"
    message: str = ""
    failed_step: int = -1
    steps_done: int = 0
    defects: list = field(default_factory=list)
    wall_seconds: float = 0.0
    cpu_seconds: float = 0.0
    events: list = field(default_factory=list)
    flow: object = field(default=None, repr=False, compare=False)
    continue_with: object = field(default=None, repr=False, compare=False)

    @property
    def ok(self):
        return self.status == "ok"

    @property
    def extinction_time(self):
        """The time the last component vanished (:attr:`events`'s
        ``extinction_time``) of a run that ended ``extinct``, NaN otherwise."""
        return float(self.events[-1]["extinction_time"]) if self.status == "extinct" \
            and self.events else float("nan")

    @property
    def surgeries(self):
        """The continuations' events: ``surgery`` (a cut), ``reextracted`` (thin parts)."""
        return [e for e in self.events if e["event"] in ("surgery", "reextracted")]

    @property
    def removed_area_share(self):
        """The area the continuations removed (``|area_removed|`` summed) over the
        initial area, 0 without one."""
        return float(sum(abs(e["area_share"]) for e in self.surgeries))

    @property
    def t_failed(self):
        """Time of the breakdown or first defect, NaN when ``ok``."""
        return float("nan") if self.ok else float(self.defects[0]["time"]) \
            if self.defects else float("nan")
