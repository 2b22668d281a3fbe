"""The contract every scheme follows, and the ways a run can end.

A scheme is a class whose instances are one flow of one surface
(:class:`SchemeFlow`, the contract; DDFV's own class is ``ddfv.Flow``); the
harness builds it from ``(vertices, faces, tau, **options)``, steps it with one of its time integrators
(:mod:`mcfbench.running.integrators`) and the shared linear solver, and
checks every new state. The scheme provides the spatial part: its state
and the linear system of one step with its operators assembled at a given
state (:meth:`SchemeFlow.system`); the integrator chooses that state, solves and
hands the solution back (:meth:`SchemeFlow.advance`). The schemes (``ddfv``,
``baselines``) import nothing from the harness, and a scheme reports what
is wrong with a state as plain ``(status, description)`` pairs
(:meth:`SchemeFlow.defects`), which the driver turns into one
:class:`FlowBreakdown` with one message format.

The statuses a run can end with are :data:`mcfbench.storage.statuses.STATUSES`.
"""

from typing import Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class SchemeFlow(Protocol):
    """One flow of one surface, stepped by the driver.

    Built as ``scheme_class(vertices, faces, tau, **options)`` with
    ``vertices`` (n, 3) float and ``faces`` (m, 3) int arrays of a
    validated manifold mesh (:func:`mcfbench.geometry.mesh.validate_mesh`).

    Attributes
    ----------
    n : int
        Current time level.
    tau : float
        Time step.
    X : (3, n_points) float array
        The state by components (DDFV: F- then T-vertices; the
        triangle-based schemes: the mesh vertices), in the numbering of the
        input mesh. Read-only (a view, or a copy for a scheme that stores
        its state in its own numbering).
    vertices : (n, 3) float array
        The mesh vertices of the current state (DDFV: the F-vertices).
    faces : (m, 3) int array
    l2_weights : (n_points,) float array
        Quadrature weights of the points of ``X`` for errors over the
        surface (they sum to its area).
    fixed : (n,) bool array
        Dirichlet (boundary) vertices, held at their initial position.
    timings : dict, optional
        Seconds by phase; the integrator adds the solves' under ``"solve"``.
    """

    n: int
    tau: float

    @property
    def X(self) -> np.ndarray: ...

    @property
    def vertices(self) -> np.ndarray: ...

    @property
    def faces(self) -> np.ndarray: ...

    @property
    def l2_weights(self) -> np.ndarray: ...

    @property
    def state(self) -> np.ndarray:
        """(3, n_points) the state ``X^n`` in the scheme's own numbering, read-only:
        what :meth:`system` takes and :meth:`advance` gives back (the arrays a
        scheme stores are never changed in place)."""

    def system(self, at, base, dt: float) -> tuple:
        """The linear system ``A X = b`` of one step, its operators assembled at ``at``.

        The step is ``M(X*) (X - B) / dt + L(X*) X = M(X*) g(X*)``
        ((I1) of :mod:`mcfbench.running.integrators`) with ``X* = at``,
        ``B = base`` (both (3, n_points), own numbering; ``None``: the current
        state, whose geometry the scheme may already have), ``M`` the scheme's
        mass-like operator, ``L`` its stiffness and ``g`` whatever it adds
        explicitly (an elimination of tangential motion, a tangential
        velocity); fixed points keep ``B``. ``A`` is an (n, n) matrix shared
        by the three components or a (3n, 3n) one acting on ``b.ravel()``;
        ``b`` is (3, n). (A scheme whose state has more rows, KLL's ``(X, nu,
        H)``, returns ``b`` with them and may return ``A`` block triangular,
        :mod:`mcfbench.running.solver`, "Systems".) The semi-implicit Euler step is ``at = base = None``
        (the state), ``dt = tau``.
        """

    def advance(self, X: np.ndarray) -> None:
        """Accept ``X`` (3, n_points, own numbering), the solution of :meth:`system`,
        as the state ``n + 1`` (a scheme may post-process it, e.g. carry its
        DDFV T-vertices with their triangles)."""

    def defects(self) -> list:
        """What is wrong with the current state: ``[(status, description)]``.

        ``status`` is one of :data:`mcfbench.storage.statuses.STATE_STATUSES`; ``description`` names
        the offending element and the measure (``"T-vertex of triangle 12:
        barycentric coordinate -0.031"``). Empty for a valid state.
        """

    def frame(self) -> dict:
        """Arrays that make one saved frame, copied, the same for every scheme:
        ``{"vertices": (n, 3)}``, the surface mesh's vertices, and for a scheme
        whose state has points besides them ``"extra_points": (k, 3)`` (DDFV's
        T-vertices; :attr:`mcfbench.running.schemes.Scheme.extra_points`), in the
        order of ``X`` (the frame-file layout of :mod:`mcfbench.storage.frames`)."""


class FlowBreakdown(RuntimeError):
    """The flow cannot go on (or, in record mode, went on past an invalid state).

    Attributes
    ----------
    status : str
        One of :data:`mcfbench.storage.statuses.STATUSES` other than ``ok``.
    step : int
        The time step ``n`` at which it happened.
    time : float
        ``t^n``.
    detail : str
        What happened, without the step and time.
    """

    def __init__(self, status, step, time, detail):
        super().__init__(f"{status} at step {step} (t = {time:.6g}): {detail}")
        self.status, self.step, self.time, self.detail = status, int(step), float(time), detail
