"""Whether a surface, or one of its connected components, has shrunk to a point or a line.

Mean curvature flow shrinks every closed surface to nothing in finite time
(a sphere of radius ``R`` at ``t = R^2 / 4``); a discrete flow stepped past
that time, or a coarse one that runs ahead of it (a cube of 12 triangles),
reaches states whose triangles are round-off sized. Assembling a scheme's
matrix on such a state divides by zero or gives a system no solver can
solve, and the run would end blaming the solver. :class:`CollapseCheck`
recognises the state before that: the driver
(:func:`mcfbench.running.driver.simulate`) asks it about every state, the
initial one included, before the next solve.

A component has *collapsed* when its coordinates are not all finite, or its
area fell below :data:`AREA_TOL` times its initial area, or its diameter (the
diagonal of its bounding box) below :data:`DIAMETER_TOL` times its initial
one. Both tolerances are relative, so the check does not depend on the scale
of the mesh. It is called *a point* when the diameter shrank about as the
square root of the area (both directions shrank), *a line* when the area
shrank much faster than the diameter squared.
"""

import math

import numpy as np

from mcfbench.geometry.measures import StateMeasures

AREA_TOL = 1e-3
"""A component whose area is below this fraction of its initial area has collapsed.

On a sphere the area falls as ``R^2``: ``1e-3`` is a radius of 3 % of the
initial one, reached in the last ``1e-3`` of the time before extinction
(``R^2 / 4``); no problem of the registry comes close (the sphere's
``t_final = 0.08`` keeps 68 % of the area). Semi-implicit schemes stepped past
extinction shrink by a factor ``R^2 / (2 tau)`` per step once ``R^2 < tau``, so
the next state after this one is typically round-off sized."""


DIAMETER_TOL = 1e-3
"""A component whose diameter is below this fraction of its initial diameter has collapsed."""


POINT = 10.0
"""Diameter ratio below ``POINT * sqrt(area ratio)``: the component shrank to a point (else a line)."""


class CollapseCheck:
    """The collapse check of one flow: the components and their initial size.

    Parameters
    ----------
    vertices : (n, 3) float array
        The initial state's mesh vertices.
    faces : (m, 3) int array
    area_tol, diameter_tol : float
        :data:`AREA_TOL`, :data:`DIAMETER_TOL`.
    measures : mcfbench.geometry.measures.StateMeasures, optional
        The measures of this mesh's states, shared with the invariant checks
        (the driver's); by default its own.

    Examples
    --------
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> check = CollapseCheck(V, F)
    >>> check(V) is None
    True
    >>> print(check(1e-4 * V))
    component 0 of 1 (4 vertices, e.g. vertex 0) shrank to a point: area 2.37e-08 (1e-08 x its initial 2.37), diameter 0.000173 (0.0001 x its initial 1.73)
    """

    def __init__(self, vertices, faces, *, area_tol=AREA_TOL, diameter_tol=DIAMETER_TOL,
                 measures=None):
        V = np.asarray(vertices, dtype=float)
        self.measures = StateMeasures(V, faces) if measures is None else measures
        self.area_tol, self.diameter_tol = float(area_tol), float(diameter_tol)
        self.count, self.labels = self.measures.count, self.measures.labels
        self._sizes = np.bincount(self.labels, minlength=self.count)
        self._first = np.unique(self.labels, return_index=True)[1]
        measured = self.measures(V)
        self.area0, self.diameter0 = measured.component_area.copy(), measured.diameter.copy()
        # one component of positive size (every surface of the registry): its ratios
        # in Python floats, as numpy divides them, without numpy's per-call overhead
        self._one = (float(self.area0[0]), float(self.diameter0[0])) if self.count == 1 \
            and self.area0[0] > 0 and self.diameter0[0] > 0 else None

    def __call__(self, vertices, measured=None):
        """What collapsed in the state ``vertices``, one sentence naming the component,
        or ``None``; ``measured``: the state's :class:`~mcfbench.geometry.measures.Measured`
        when the caller has it (the driver, for both of its checks), else measured here."""
        V = np.asarray(vertices, dtype=float)
        if measured is None:
            measured = self.measures(V)
        area, diameter = measured.component_area, measured.diameter
        if self._one is not None:
            a, d = float(area[0]), float(diameter[0])
            if math.isfinite(a) and math.isfinite(d) and not (
                    a / self._one[0] < self.area_tol or d / self._one[1] < self.diameter_tol):
                return None
        if not (np.isfinite(area).all() and np.isfinite(diameter).all()):
            bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
            if len(bad):
                c = int(self.labels[bad[0]])
                return (f"non-finite coordinates at {len(bad)} vertex(es), e.g. vertex "
                        f"{int(bad[0])} of component {c} of {self.count}")
        with np.errstate(divide="ignore", invalid="ignore"):
            a_ratio, d_ratio = area / self.area0, diameter / self.diameter0
        collapsed = np.flatnonzero((a_ratio < self.area_tol) | (d_ratio < self.diameter_tol))
        if not len(collapsed):
            return None
        c = int(collapsed[np.argmin(a_ratio[collapsed])])
        shape = "a point" if d_ratio[c] <= POINT * np.sqrt(a_ratio[c]) else "a line"
        more = f" ({len(collapsed)} components collapsed)" if len(collapsed) > 1 else ""
        return (f"component {c} of {self.count} ({self._sizes[c]} vertices, e.g. vertex "
                f"{int(self._first[c])}) shrank to {shape}: area {area[c]:.3g} "
                f"({a_ratio[c]:.3g} x its initial {self.area0[c]:.3g}), diameter "
                f"{diameter[c]:.3g} ({d_ratio[c]:.3g} x its initial {self.diameter0[c]:.3g})"
                + more)
