"""Semi-implicit time stepping (2.1) of the DDFV scheme.

One step solves ``(I + tau diag(1/chi^{n-1}) K^{n-1}) X^n = X^{n-1}``
((2.10), (2.13)) for the stacked ``X = [F; T]`` (stored by components,
shape (3, n_F + n_T)) as one block system by BiCGStab.

Open surfaces: boundary F-vertices keep their position (1.2); see
:mod:`ddfv.assembly`. With ``tangential="eliminate"`` the right-hand side
becomes ``X^{n-1} - tau (h - (h.N) N)`` (3.6), where
``h = -diag(1/chi) K X^{n-1} = (X^{n-1} - A X^{n-1}) / tau`` is the
scheme's own discrete Laplacian of the previous state (zero at Dirichlet
vertices) and ``N`` the vertex normals of
:func:`ddfv.geometry.vertex_normals`.

Warm start: ``X^n`` is predicted by linear extrapolation
``2 X^{n-1} - X^{n-2}`` (``X^0`` at the first step), whose residual is
O(tau^2) instead of the O(tau) of ``X^{n-1}``; ``warm_start="previous"``
starts from ``X^{n-1}`` (see ``ddfv/README.md``).
"""

from dataclasses import dataclass
from functools import cached_property

import time

import numpy as np
from tqdm import tqdm

from .assembly import Assembler
from .geometry import (covolume_areas, diamond_geometry, t_barycentric, triangle_areas,
                       vertex_normals)
from .solver import apply_block, bicgstab
from .t_vertices import initial_t_vertices
from .topology import diamond_mesh

DEFAULT_RTOL = 1e-9
WARM_STARTS = ("extrapolate", "previous")
TANGENTIAL = ("none", "eliminate")


class FlowBreakdown(RuntimeError):
    """The flow cannot go on: the solver failed or the mesh degenerated.

    Attributes
    ----------
    status : str
        ``"solver_failed"`` or ``"degenerated"``.
    step : int
        The time step ``n`` at which it happened.
    time : float
        ``t^n``.
    """

    def __init__(self, status, step, time, message):
        super().__init__(message)
        self.status, self.step, self.time = status, step, time

    @classmethod
    def solver_failed(cls, step, tau, info, rtol):
        """BiCGStab (``info``: :class:`~ddfv.solver.SolveInfo`) missed ``rtol``."""
        t = step * tau
        return cls("solver_failed", step, t,
                   f"BiCGStab did not converge at step {step} (t = {t:.6g}): "
                   f"relative residual {info.residual:.3e} > rtol {rtol:.1e} "
                   f"after {info.iterations} iterations")

    @classmethod
    def degenerated(cls, step, tau, what):
        """The state of time level ``step`` is degenerate: ``what`` says how."""
        t = step * tau
        return cls("degenerated", step, t, f"mesh degenerated at step {step} (t = {t:.6g}): {what}")


def collapsed_cells(measure, threshold, cell):
    """Describe the cells whose ``measure`` is not above ``threshold``, or None.

    Parameters
    ----------
    measure : (m,) float array
        Areas of the cells (NaN counts as collapsed).
    threshold : float
    cell : str
        Name of a cell in the message, e.g. ``"diamond cell"``.
    """
    collapsed = np.flatnonzero(~(measure > threshold))
    if len(collapsed) == 0:
        return None
    return f"{len(collapsed)} {cell}(s) collapsed, e.g. {cell} {int(collapsed[0])}"


def validate_vertices(vertices, faces):
    """Check coordinates and triangle areas of an input surface.

    Raises
    ------
    ValueError
        Non-finite coordinates or a (numerically) zero-area triangle,
        naming the offending vertices or triangles.
    """
    V = np.asarray(vertices, dtype=float)
    if V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"vertices must have shape (n, 3), got {V.shape}")
    bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
    if len(bad):
        raise ValueError(f"NaN or inf coordinates at vertex(es) {bad[:10].tolist()}")
    faces = np.asarray(faces)
    if len(faces) and faces.max() < len(V):
        area = triangle_areas(V, faces)
        p = V[faces]
        scale = np.linalg.norm(p - p[:, [1, 2, 0]], axis=2).max(axis=1) ** 2
        zero = np.flatnonzero(area <= 1e-12 * np.maximum(scale, np.finfo(float).tiny))
        if len(zero):
            raise ValueError(f"zero-area (degenerate) triangle(s): {zero[:10].tolist()}")
    return V


class Flow:
    """DDFV mean curvature flow of one triangulated surface.

    Parameters
    ----------
    vertices : (n_f, 3) float array
        Initial F-vertices ``F^0``.
    faces : (n_t, 3) int array
        Consistently oriented triangles.
    tau : float
        Time step.
    T0 : (n_t, 3) float array, optional
        Initial T-vertices; by default from ``t_init``.
    t_init : {"paper", "barycenter", "exact"}
        T-vertex initialisation (see :mod:`ddfv.t_vertices`).
    rtol : float
        BiCGStab relative tolerance ``|r| <= rtol |X^{n-1}|``.
    maxiter : int
        BiCGStab iteration limit per step.
    warm_start : {"extrapolate", "previous"}
        Initial guess of BiCGStab (see module docstring).
    tangential : {"none", "eliminate"}
        ``"eliminate"`` removes the tangential part of the discrete mean
        curvature vector from the velocity (3.6).
    dual_length : {"broken", "chord"}
        Length of the dual curves ``|gamma|``: the paper's broken line (2.5)
        or the chord (see :func:`ddfv.geometry.diamond_geometry`).

    Attributes
    ----------
    F, T : float arrays
        Current state ``F^n``, ``T^n``.
    n : int
        Current time level.
    timings : dict
        Seconds spent so far in ``"geometry"`` (including the covolumes and
        the checks of each new state), ``"assembly"`` and ``"solve"``.
    """

    def __init__(self, vertices, faces, tau, *, T0=None, t_init="paper",
                 rtol=DEFAULT_RTOL, maxiter=1000, warm_start="extrapolate",
                 tangential="none", dual_length="broken"):
        if not (np.isfinite(tau) and tau > 0):
            raise ValueError(f"tau must be a positive number, got {tau!r}")
        if not (0 < rtol < 1):
            raise ValueError(f"rtol must lie in (0, 1), got {rtol!r}")
        if warm_start not in WARM_STARTS:
            raise ValueError(f"unknown warm_start {warm_start!r}; choose one of "
                             f"{', '.join(WARM_STARTS)}")
        if tangential not in TANGENTIAL:
            raise ValueError(f"unknown tangential {tangential!r}; choose one of "
                             f"{', '.join(TANGENTIAL)}")
        self.mesh = diamond_mesh(faces, len(vertices))
        F = validate_vertices(vertices, self.mesh.faces)
        T = initial_t_vertices(F, self.mesh, t_init) if T0 is None \
            else np.asarray(T0, dtype=float)
        if T.shape != (self.mesh.n_t, 3):
            raise ValueError(f"T0 must have shape {(self.mesh.n_t, 3)}, got {T.shape}")
        self.tau, self.rtol, self.maxiter = float(tau), float(rtol), int(maxiter)
        self.warm_start, self.tangential = warm_start, tangential
        self.dual_length = dual_length
        self.n = 0
        self._X = np.ascontiguousarray(np.concatenate([F, T]).T)
        self._X_prev = self._X
        self._assembler = Assembler(self.mesh)
        self.timings = {"geometry": 0.0, "assembly": 0.0, "solve": 0.0}
        try:
            self._check_geometry()
        except FlowBreakdown as err:
            raise ValueError(f"initial surface is degenerate: {err}") from None

    @property
    def X(self):
        """(3, n_f + n_t) read-only view of ``[F^n; T^n]`` by components."""
        view = self._X.view()
        view.flags.writeable = False
        return view

    @property
    def F(self):
        """(n_f, 3) view of the F-vertices ``F^n``."""
        return self._X[:, :self.mesh.n_f].T

    @property
    def T(self):
        """(n_t, 3) view of the T-vertices ``T^n``."""
        return self._X[:, self.mesh.n_f:].T

    @property
    def t(self):
        return self.n * self.tau

    @cached_property
    def geometry(self):
        """:class:`~ddfv.geometry.DiamondGeometry` of the current state."""
        return diamond_geometry(self.mesh, self.F, self.T, self.dual_length)

    @cached_property
    def covolumes(self):
        """(n_f + n_t,) covolume areas ``chi^n``, F-vertices first."""
        return np.concatenate(covolume_areas(self.mesh, self.geometry))

    @property
    def l2_weights(self):
        """Quadrature weights of the L2 error (3.2): ``chi^n / 2`` (the F- and
        the T-covolumes each tile the surface once)."""
        return 0.5 * self.covolumes

    def t_min_barycentric(self):
        """Smallest barycentric coordinate of any T-vertex in its triangle."""
        return float(t_barycentric(self.F, self.T, self.mesh.faces).min())

    def step(self):
        """Advance one time step.

        Returns
        -------
        SolveInfo

        Raises
        ------
        FlowBreakdown
            BiCGStab did not converge (the state stays at ``n - 1``) or the
            new state is degenerate (the state is the degenerate ``X^n``).
        """
        clock = time.perf_counter()
        geometry, covolumes = self.geometry, self.covolumes
        self._tick("geometry", clock)
        clock = time.perf_counter()
        A = self._assembler.system(geometry, covolumes, self.tau)
        rhs = self._X
        if self.tangential == "eliminate":
            h = (self._X - apply_block(A, self._X)) / self.tau      # h^{n-1}
            N = vertex_normals(self.mesh, self.geometry)              # N^{n-1}
            rhs = self._X - self.tau * (h - (h * N).sum(axis=0) * N)  # (3.6)
        x0 = self._X
        if self.warm_start == "extrapolate":
            x0 = 2.0 * self._X - self._X_prev
        clock = self._tick("assembly", clock)
        X, info = bicgstab(A, rhs, x0, rtol=self.rtol, maxiter=self.maxiter)
        clock = self._tick("solve", clock)
        if not info.converged:
            raise FlowBreakdown.solver_failed(self.n + 1, self.tau, info, self.rtol)
        self._X_prev, self._X = self._X, X
        self.n += 1
        for name in ("geometry", "covolumes"):
            self.__dict__.pop(name, None)
        self._check_geometry()
        self._tick("geometry", clock)
        return info

    def _tick(self, phase, since):
        now = time.perf_counter()
        self.timings[phase] += now - since
        return now

    def _check_geometry(self):
        if not np.isfinite(self._X).all():
            raise FlowBreakdown.degenerated(self.n, self.tau, "non-finite coordinates")
        J = self.geometry.J
        if self.n == 0:
            self._J0 = J.mean()
        # collapsed against the mesh now (a local collapse) or at n = 0 (the
        # surface shrinking to a point)
        what = collapsed_cells(J, max(1e-10 * J.mean(), 1e-12 * self._J0), "diamond cell")
        if what:
            raise FlowBreakdown.degenerated(self.n, self.tau, what)


@dataclass
class Trajectory:
    """Result of :func:`simulate`.

    Attributes
    ----------
    F : (frames, n_f, 3) float array
    T : (frames, n_t, 3) float array
    t : (frames,) float array
        Frame 0 is the initial state, the last frame the final (or last
        computed) state.
    steps : (frames,) int array
        Time level of each frame.
    iterations : (n_steps,) int array
        BiCGStab iterations of each completed step.
    t_min_barycentric : (n_steps + 1,) float array
        The T monitor of every time level reached.
    status : str
        ``"ok"``, ``"solver_failed"`` or ``"degenerated"``.
    message : str
        Empty when ``status == "ok"``.
    failed_step : int
        Time step of the breakdown, ``-1`` when ``status == "ok"``.
    timings : dict
        :attr:`Flow.timings` at the end.
    faces : (n_t, 3) int array
    """

    F: np.ndarray
    T: np.ndarray
    t: np.ndarray
    steps: np.ndarray
    iterations: np.ndarray
    t_min_barycentric: np.ndarray
    faces: np.ndarray
    status: str = "ok"
    message: str = ""
    failed_step: int = -1
    timings: dict = None


def simulate(vertices, faces, tau, steps, *, save_every=1, observer=None,
             progress=False, **flow_options):
    """Run the DDFV flow for ``steps`` time steps.

    Parameters
    ----------
    vertices : (n_f, 3) float array
    faces : (n_t, 3) int array
    tau : float
    steps : int
    save_every : int
        Keep every ``save_every``-th time level as a frame (the first and
        the last are always kept). ``0`` keeps only those two.
    observer : callable, optional
        ``observer(flow)`` is called at every time level, ``n = 0`` included.
    progress : bool
        Show a progress bar for runs longer than two seconds.
    **flow_options
        Passed to :class:`Flow` (``T0``, ``t_init``, ``rtol``, ``maxiter``,
        ``warm_start``, ``tangential``, ``dual_length``).

    Returns
    -------
    Trajectory
        On a breakdown, ``status`` and ``message`` say what happened and
        everything computed before is kept.
    """
    flow = Flow(vertices, faces, tau, **flow_options)
    monitor = []

    def record(flow):
        monitor.append(flow.t_min_barycentric())
        if observer is not None:
            observer(flow)

    run = run_steps(flow, steps, save_every=save_every, observer=record,
                    progress=progress, state=lambda f: (f.F.copy(), f.T.copy()))
    F, T = run.frames
    return Trajectory(
        F=F, T=T, t=run.steps * flow.tau, steps=run.steps, iterations=run.iterations,
        t_min_barycentric=np.array(monitor), faces=flow.mesh.faces,
        status=run.status, message=run.message, failed_step=run.failed_step,
        timings=dict(flow.timings))


@dataclass
class Steps:
    """What :func:`run_steps` collected.

    Attributes
    ----------
    steps : (frames,) int array
        Time level of each frame.
    frames : tuple of (frames, ...) arrays
        One stacked array per entry of the ``state`` of each frame.
    iterations : (n_steps,) int array
    status, message : str
    failed_step : int
    """

    steps: np.ndarray
    frames: tuple
    iterations: np.ndarray
    status: str
    message: str
    failed_step: int


def run_steps(flow, steps, *, save_every, state, observer=None, progress=False):
    """Step a flow and keep frames: the driver of every scheme's ``simulate``.

    Parameters
    ----------
    flow : object
        With ``step() -> SolveInfo`` (raising :class:`FlowBreakdown`) and
        the current time level ``n``.
    steps : int
    save_every : int
        Keep every ``save_every``-th time level (the first and the last are
        always kept); ``0`` keeps only those two.
    state : callable
        ``state(flow)`` -> tuple of arrays, copied, that make a frame.
    observer : callable, optional
        ``observer(flow)`` at every time level reached, ``n = 0`` included.
    progress : bool
        A progress bar for runs longer than two seconds.

    Returns
    -------
    Steps
        On a breakdown ``status``, ``message`` and ``failed_step`` say what
        happened; the frames and counts of the levels before are kept (and
        the state after a degenerate step as the last frame).
    """
    if int(steps) != steps or steps < 0:
        raise ValueError(f"steps must be a whole number >= 0, got {steps!r}")
    if int(save_every) != save_every or save_every < 0:
        raise ValueError(f"save_every must be a whole number >= 0, got {save_every!r}")
    frames, iterations = [], []
    status, message, failed = "ok", "", -1

    def save():
        frames.append((flow.n, *state(flow)))

    if observer is not None:
        observer(flow)
    save()
    with tqdm(total=int(steps), delay=2.0, disable=not progress, unit="step") as bar:
        for _ in range(int(steps)):
            try:
                iterations.append(flow.step().iterations)
            except FlowBreakdown as err:
                status, message, failed = err.status, str(err), err.step
                break
            finally:
                bar.update()
            if observer is not None:
                observer(flow)
            if save_every and flow.n % save_every == 0:
                save()
    if frames[-1][0] != flow.n:
        save()
    n, *arrays = zip(*frames)
    return Steps(steps=np.array(n), frames=tuple(np.array(a) for a in arrays),
                 iterations=np.array(iterations, dtype=int), status=status,
                 message=message, failed_step=failed)
