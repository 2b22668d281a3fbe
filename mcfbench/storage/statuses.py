"""The ways a run can end: part of the flow contract and of every run record.

Statuses
--------
``ok``
    Every step done and every state valid.
``extinct``
    The flow's own end: the last closed component vanished round, to a point
    (isoperimetric ratio near a sphere's) or to a circle (a torus's tube round
    about its core circle), before the final time
    (:mod:`mcfbench.geometry.collapse`); the message names the component and its
    extinction time. Every state before it valid: the run *reached the end*
    (:data:`REACHED`), not a breakdown.
``solver_failed``
    The iteration limit was reached without meeting the tolerance.
``solver_breakdown``
    A Krylov breakdown (``rho = 0``, ``(r_hat, v) = 0`` or ``omega = 0``).
``solver_stagnated``
    The residual stopped decreasing above the tolerance.
``degenerated``
    Non-finite coordinates or collapsed cells (diamonds, triangles), a
    connected component that shrank to a point or a line without vanishing round
    (a flattening, a needle, a fold; the driver's check
    before every solve, :mod:`mcfbench.geometry.collapse`), or a linear solver
    that failed on a mesh whose smallest angle had collapsed
    (:meth:`mcfbench.geometry.invariants.FlowInvariants.quality_collapse`: the
    mesh's verdict, not the solver's).
``t_escaped``
    A T-vertex left its triangle (DDFV, Section 2.2.2 of the paper): its
    projection onto the plane of the triangle has a negative barycentric
    coordinate.
``inverted``
    A triangle's normal flipped against its neighbours (the surface folded):
    checked on the mesh of every scheme by the driver
    (:mod:`mcfbench.geometry.invariants`).
``area_grew``
    The area of the mesh grew beyond a measured tolerance above its smallest
    earlier value: mean curvature flow never increases the area
    (:mod:`mcfbench.geometry.invariants`).
``unsupported``
    The scheme refused the input (e.g. a surface with boundary for a scheme
    that has none); nothing was computed.
"""

STATUSES = ("ok", "extinct", "solver_failed", "solver_breakdown", "solver_stagnated", "degenerated",
            "t_escaped", "inverted", "area_grew", "unsupported")
SOLVER_STATUSES = ("solver_failed", "solver_breakdown", "solver_stagnated")
STATE_STATUSES = ("degenerated", "t_escaped", "inverted", "area_grew")
REACHED = ("ok", "extinct")
"""The statuses of a run that reached its end: the final time (or a steady state), or
the flow's extinction. The tables and findings count the others as breakdowns."""


def reached(status):
    """Whether a run of ``status`` reached its end (:data:`REACHED`)."""
    return status in REACHED
