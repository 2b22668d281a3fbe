"""What every mean curvature flow must do, checked on every state of every run.

Mean curvature flow is the gradient flow of the area: on a closed surface,
and on one whose boundary is held fixed,

    d|Gamma| / dt = - int_Gamma H^2  <=  0,

so the area never grows; and a flow of an embedded surface does not fold
it over itself. A discrete flow that violates either has stopped being a
mean curvature flow, whatever its solver says: a tangential motion added
explicitly can make the area grow tenfold while every linear solve
converges. :class:`FlowInvariants` checks both on the mesh of every state
(the mesh vertices of every scheme, DDFV's F-vertices included), for every
scheme of the registry and any added later, through the driver
(:func:`mcfbench.running.driver.simulate`):

``area_grew``
    The area of the mesh exceeds the smallest area of the earlier states by
    more than :data:`AREA_TOL` of it.
``inverted``
    A triangle's normal points against the mean normal of its
    edge-neighbours (:func:`mcfbench.geometry.metrics.neighbour_cosines`)
    and did not at step 0.

It also follows the smallest angle of the mesh, so that a linear solver
that fails on a mesh whose quality collapsed is reported as the mesh's
verdict (:meth:`FlowInvariants.quality_collapse`), not the solver's.

Why the tolerance is what it is: Dziuk's cotangent scheme and BGN's scheme
decrease the discrete area unconditionally (Dziuk 1991; Barrett, Garcke,
Nuernberg 2008, Theorem 2.1), but DDFV's mesh of F-vertices is not the
surface whose energy its scheme decreases, and second-order time stepping
gives no such estimate. ``benchmarks/area_fluctuation.py`` measures the
largest growth of the area over its running minimum of every scheme of the
registry, with both integrators, on the problems with an exact or
reference answer (levels 1-2, 581 runs): among the 385 that end ``ok`` it is
at most 2.1e-4 (``ddfv-eliminate`` on the catenoid, level 2, near its
steady state; 1.5e-4 at level 1); the schemes' other runs grow by less than
7e-5 or not at all. :data:`AREA_TOL` is five times that, and a thousand
times below the smallest growth of the broken runs that motivated the check
(a factor 2.5). The runs it stops there are five BDF2 runs at the pinch of
the torus and the dumbbell.
"""

import numpy as np

from mcfbench.geometry.measures import StateMeasures
from mcfbench.geometry.metrics import neighbour_cosines

AREA_TOL = 1e-3
"""Largest relative growth of the area over its smallest earlier value."""

ANGLE_COLLAPSE = 0.1
"""The mesh's quality has collapsed when its smallest angle is below this fraction of
its initial smallest angle and below :data:`ANGLE_FLOOR`."""

ANGLE_FLOOR = 1.0
"""Degrees: a smallest angle above this never counts as a collapse."""


class FlowInvariants:
    """The invariant checks of one flow: its initial mesh, the smallest area so far.

    Parameters
    ----------
    vertices : (n, 3) float array
        The initial state's mesh vertices.
    faces : (m, 3) int array
        Consistently oriented triangles.
    area_tol : float
        :data:`AREA_TOL`.
    measures : mcfbench.geometry.measures.StateMeasures, optional
        The measures of this mesh's states (area, smallest angle, folds), shared
        with the collapse check (the driver's); by default its own.

    Examples
    --------
    >>> from mcfbench.geometry.spheres import icosphere
    >>> V, F = icosphere(1)
    >>> check = FlowInvariants(V, F)
    >>> check(0.9 * V, 1)
    []
    >>> [(status, detail)] = check(V, 2)
    >>> status
    'area_grew'
    >>> print(detail)
    the area grew to 11.7 at step 2, 0.235 above its smallest value 9.45 (step 1): mean curvature flow never increases the area (tolerance 0.001)
    """

    def __init__(self, vertices, faces, *, area_tol=AREA_TOL, measures=None):
        V = np.asarray(vertices, dtype=float)
        self.measures = StateMeasures(V, faces) if measures is None else measures
        self.faces, self.neighbours = self.measures.faces, self.measures.neighbours
        self.folded0 = self.measures.folded0
        self.area_tol = float(area_tol)
        measured = self.measures(V)
        self.smallest_area, self.smallest_area_step = measured.area, 0
        self.angle0 = self.angle = measured.angle
        self.angle_step = 0
        self.collapsed_since = None

    @property
    def angle_threshold(self):
        """Degrees below which the smallest angle counts as collapsed."""
        return min(ANGLE_FLOOR, ANGLE_COLLAPSE * self.angle0)

    def __call__(self, vertices, step, measured=None):
        """The invariants the state ``vertices`` of time level ``step`` violates;
        ``measured``: the state's :class:`~mcfbench.geometry.measures.Measured` when the
        caller has it (the driver, for both of its checks), else measured here.

        Returns
        -------
        list of (status, detail)
            ``status`` ``"inverted"`` or ``"area_grew"``; ``detail`` names the
            triangle or the growth. Empty for a state that keeps both.
        """
        V = np.asarray(vertices, dtype=float)
        if measured is None:
            measured = self.measures(V)
        area, self.angle, folded = measured.area, measured.angle, measured.folded
        self.angle_step = int(step)
        if not self.angle >= self.angle_threshold:
            if self.collapsed_since is None:
                self.collapsed_since = int(step)
        else:
            self.collapsed_since = None
        violations = []
        if folded:
            violations.append(("inverted", self._folded(V)))
        if area > self.smallest_area * (1.0 + self.area_tol):
            growth = area / self.smallest_area - 1.0 if self.smallest_area > 0 else np.inf
            violations.append(("area_grew", (
                f"the area grew to {area:.3g} at step {int(step)}, {growth:.3g} above its "
                f"smallest value {self.smallest_area:.3g} (step {self.smallest_area_step}): "
                f"mean curvature flow never increases the area (tolerance {self.area_tol:g})")))
        elif area < self.smallest_area:
            self.smallest_area, self.smallest_area_step = area, int(step)
        return violations

    def _folded(self, V):
        """The sentence on the triangles folded now and not at step 0."""
        cosine = neighbour_cosines(V, self.faces, self.neighbours)
        folded = np.flatnonzero(~(cosine >= 0.0) & ~self.folded0)
        worst = int(folded[np.argmin(cosine[folded])])
        return (f"triangle {worst} folded against its neighbours (cosine "
                f"{cosine[worst]:.3g} with their mean normal; {len(folded)} triangle(s) "
                "folded that were not at step 0)")

    def quality_collapse(self):
        """The sentence on a collapsed mesh quality of the last state checked, or None.

        The smallest angle counts as collapsed below :attr:`angle_threshold`
        (:data:`ANGLE_COLLAPSE` times the initial one, at most :data:`ANGLE_FLOOR`
        degrees); the sentence says since when.
        """
        if self.collapsed_since is None:
            return None
        return (f"the mesh degenerated: smallest angle {self.angle:.3g} degrees at step "
                f"{self.angle_step} ({self.angle0:.3g} at step 0), below "
                f"{self.angle_threshold:.3g} since step {self.collapsed_since}")
