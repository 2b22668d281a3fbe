"""The contract every scheme follows, and the ways a run can end.

A scheme is a class whose instances are one flow of one surface
(:class:`Flow`); the harness builds it from ``(vertices, faces, tau,
**options)``, steps it with the shared linear solver and checks every new
state. The schemes (``ddfv``, ``baselines``) import nothing from the
harness: the solver is passed to :meth:`Flow.step` as a function, and a
scheme reports what is wrong with a state as plain ``(status, description)``
pairs (:meth:`Flow.defects`), which the driver turns into one
:class:`FlowBreakdown` with one message format.

Statuses
--------
``ok``
    Every step done and every state valid.
``solver_failed``
    The iteration limit was reached without meeting the tolerance.
``solver_breakdown``
    A Krylov breakdown (``rho = 0``, ``(r_hat, v) = 0`` or ``omega = 0``).
``solver_stagnated``
    The residual stopped decreasing above the tolerance.
``degenerated``
    Non-finite coordinates or collapsed cells (diamonds, triangles).
``t_escaped``
    A T-vertex left its triangle (DDFV, Section 2.2.2 of the paper): its
    projection onto the plane of the triangle has a negative barycentric
    coordinate.
``inverted``
    A triangle's normal flipped against its neighbours (the surface folded).
``unsupported``
    The scheme refused the input (e.g. a surface with boundary for a scheme
    that has none); nothing was computed.
"""

from typing import Callable, Protocol, runtime_checkable

import numpy as np

STATUSES = ("ok", "solver_failed", "solver_breakdown", "solver_stagnated", "degenerated",
            "t_escaped", "inverted", "unsupported")
SOLVER_STATUSES = ("solver_failed", "solver_breakdown", "solver_stagnated")
STATE_STATUSES = ("degenerated", "t_escaped", "inverted")


@runtime_checkable
class Flow(Protocol):
    """One flow of one surface, stepped by the driver.

    Built as ``scheme_class(vertices, faces, tau, **options)`` with
    ``vertices`` (n, 3) float and ``faces`` (m, 3) int arrays of a
    validated manifold mesh (:func:`mcfbench.mesh.validate_mesh`).

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

    def step(self, solve: Callable) -> object:
        """Advance one time step.

        ``solve(A, b, x0) -> (x, info)`` solves ``A x = b`` for a (3, n)
        block ``b`` from ``x0`` (``A`` an (n, n) matrix shared by the three
        components or a (3n, 3n) matrix acting on ``b.ravel()``); it raises
        when the solve fails, and the scheme lets that propagate with its
        state unchanged. Returns ``info``.
        """

    def defects(self) -> list:
        """What is wrong with the current state: ``[(status, description)]``.

        ``status`` is one of :data:`STATE_STATUSES`; ``description`` names
        the offending element and the measure (``"T-vertex of triangle 12:
        barycentric coordinate -0.031"``). Empty for a valid state.
        """

    def frame(self) -> dict:
        """Arrays that make one saved frame, copied: ``{"F": ..., "T": ...}``
        for DDFV, ``{"V": ...}`` for the others."""


class FlowBreakdown(RuntimeError):
    """The flow cannot go on (or, in record mode, went on past an invalid state).

    Attributes
    ----------
    status : str
        One of :data:`STATUSES` other than ``ok``.
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
