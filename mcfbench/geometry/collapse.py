"""Whether a surface, or one of its connected components, has shrunk to a point or a
line, and whether it vanished round: the flow's own end (extinction) or a breakdown.

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

Extinction
----------
A closed component that vanishes *round* has reached the flow's end, not a
breakdown (issue #44, item 3; issue #45, item 2): status ``extinct``
(:class:`Collapse`). Three ways to vanish round, each with the time it has left
under the velocity ``H n`` (``H`` the sum of the principal curvatures):

*a point*
    A sphere-like component (Euler characteristic 2) whose isoperimetric
    ratio ``q = 36 pi V^2 / A^3`` (1 for a sphere, Polya-Szego) is at least
    :data:`ROUND_POINT`. A round sphere of area ``A = 4 pi R^2`` has
    ``R^2 / 4 = A / (16 pi)`` left.
*a circle*
    A torus-like component (Euler characteristic 0) whose tube is round
    around a planar circle (:func:`tube_fit`: every vertex within
    :data:`ROUND_TUBE` of the mean tube radius ``r`` from the circle, and
    ``2 V / A``, which is ``r`` exactly for a tube of round cross-section
    around any closed curve (``A = 2 pi r L``, ``V = pi r^2 L``), within
    :data:`ROUND_TUBE` of it): the torus (2, 0.5) collapsing onto its core
    circle. A round tube thin against its circle shrinks as a cylinder,
    ``r' = -1 / r``: ``r^2 / 2`` left, with ``r = 2 V / A``.
*a curve*
    A torus-like component that is no round tube about a planar circle but one
    about a curve in space (a knotted tube: the raw corpus's quadknot): its mean
    curvature ``|H n|`` (:func:`mean_curvature_vectors`) within :data:`ROUND_TUBE`
    of ``1 / r`` at every vertex, ``r = 2 V / A`` (Weyl's tube formula gives
    ``A = 2 pi r L`` and ``V = pi r^2 L`` about any closed curve of length ``L``; a
    tube of radius ``r`` about a curve of curvature ``kappa`` has ``H = 1 / r +
    kappa cos(theta) / (1 - r kappa cos(theta))``, so the bound also asks the tube to
    be thin against its curve, ``r kappa`` below about a third). It shrinks as the
    circle's, ``r^2 / 2`` left, while its core moves by the curvature ``kappa``, slower:
    the level-set flow's tube vanishes onto the curve (Evans and Spruck 1991; Altschuler,
    Angenent and Giga 1995 for the circle).

A closed component is tested once its area fell below :data:`WATCH` of its initial
one (its volume is measured then, in numpy, only for such states). It is
*extinct* when it is round and either collapsed (the tolerances above) or has
less than :data:`EXTINCTION_STEPS` time steps left (``tau`` given, and a step to
follow): stepping on would take the semi-implicit schemes into the round-off
states above. Its
*extinction time* is the state's time plus the time it has left (the exact
flow's, from the round component's area and volume): within a few steps of
the end the schemes lag the exact radius by ``O(tau)`` per step (the implicit
step shrinks ``R^2`` by ``4 tau / (1 + 2 tau / R^2)^2``-ish, not ``4 tau``),
so the extrapolation from a resolved state is closer to the flow's time than
the step at which the discrete component happens to fall below a tolerance.
A collapse that is not round (a flattening, a needle, a cube of 12 triangles,
a fold) stays ``degenerated``.
"""

import math
from typing import NamedTuple

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

WATCH = 0.25
"""A component is tested for a round vanishing once its area is below this fraction of
its initial one (a sphere at half its radius)."""

ROUND_POINT = 0.8
"""Smallest isoperimetric ratio ``36 pi V^2 / A^3`` of a component that vanishes as a
round point. The discrete flows keep the icosphere's: 0.956 (level 1), 0.988 (level 2)
up to the end; a cube has ``pi / 6 = 0.524``, a spheroid of axes 2:2:1 0.76."""

ROUND_TUBE = 0.5
"""Largest relative spread of a tube's radius (:func:`tube_fit`) that vanishes as a
round circle."""

EXTINCTION_STEPS = 2.0
"""A round component with less than this many time steps left (its time left, above)
is extinct."""


class Collapse(NamedTuple):
    """What :class:`CollapseCheck` found in a state; ``str()`` is its sentence.

    Attributes
    ----------
    status : str
        ``"extinct"`` (every component found vanished round) or ``"degenerated"``.
    detail : str
        One sentence naming the component(s), their area, diameter (and for an
        extinction the kind, the volume and the extinction time).
    components : tuple of int
        The components found (extinct ones for ``"extinct"``).
    kinds : tuple of str
        ``"point"``, ``"circle"``, ``"curve"`` (round) or ``"line"``, ``"point"`` of
        each.
    areas, volumes, times : tuple of float
        Area, enclosed volume and extinction time (the state's time plus the
        time the round component has left; NaN when not round or no time given)
        of each.
    """

    status: str
    detail: str
    components: tuple = ()
    kinds: tuple = ()
    areas: tuple = ()
    volumes: tuple = ()
    times: tuple = ()

    def __str__(self):
        return self.detail


def component_topology(faces, labels, count):
    """The Euler characteristic ``chi = V - E + F`` of every connected component, and
    whether it is closed (every edge of it shared by two triangles).

    Parameters
    ----------
    faces : (m, 3) int array
    labels : (n,) int array
        Component of every vertex (:func:`mcfbench.geometry.measures.vertex_components`).
    count : int

    Returns
    -------
    chi : (count,) int array
        2 for a sphere, 0 for a torus, ``2 - 2 g - b`` in general.
    closed : (count,) bool array
    """
    F = np.asarray(faces, dtype=np.int64)
    # every edge once as the key min * n + max, its first end key // n: the rows of
    # np.unique(..., axis=0) in the same order (metrics.mean_edge_length's), 13 x
    # faster (face's 51 000 edges: 7 ms against 100 ms, at every remesh)
    n = int(F.max()) + 1 if F.size else 1
    sides = np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    key, seen = np.unique(sides[:, 0] * n + sides[:, 1], return_counts=True)
    first = key // n
    chi = (np.bincount(labels, minlength=count)
           - np.bincount(labels[first], minlength=count)
           + np.bincount(labels[F[:, 0]], minlength=count))
    return chi, np.bincount(labels[first[seen == 1]], minlength=count) == 0


def component_volumes(vertices, faces, face_label, count):
    """The enclosed volume of every component, ``sum a . (b x c) / 6`` over its
    triangles (positive for outward-oriented closed components).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    face_label : (m,) int array
    count : int

    Returns
    -------
    (count,) float array
    """
    a, b, c = (np.asarray(vertices, dtype=float)[np.asarray(faces)[:, k]] for k in range(3))
    return np.bincount(face_label, np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0,
                       minlength=count)


def mean_curvature_vectors(vertices, faces):
    """``H n = -M^{-1} L X`` at every vertex (libigl's cotangent Laplacian ``L`` and
    Voronoi mass ``M``): ``2 / R`` times the inward normal on a sphere of radius ``R``.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (n, 3) float array
    """
    import igl  # on first use

    V, F = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    L = igl.cotmatrix(V, F)
    mass = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    return (L @ V) / mass[:, None]


def tube_fit(points):
    """The planar circle that ``points`` (a thin torus) surround, and the tube's radius.

    The circle's plane is the least-squares plane of the points (the singular vector
    of their smallest spread), its centre their mean, its radius ``R`` their mean
    distance ``rho`` from the axis; each point's distance from the circle is
    ``d = sqrt((rho - R)^2 + z^2)`` (``z`` its height above the plane).

    Parameters
    ----------
    points : (k, 3) float array

    Returns
    -------
    R, r, spread : float
        The circle's radius, the tube's mean radius ``mean(d)`` and
        ``max |d - r| / r``.

    Examples
    --------
    >>> u, v = np.meshgrid(np.arange(16) * np.pi / 8, np.arange(8) * np.pi / 4)
    >>> P = np.stack([(2 + 0.1 * np.cos(v)) * np.cos(u), (2 + 0.1 * np.cos(v)) * np.sin(u),
    ...               0.1 * np.sin(v)], axis=-1).reshape(-1, 3)
    >>> [round(x, 3) for x in tube_fit(P)]
    [2.0, 0.1, 0.0]
    """
    P = np.asarray(points, dtype=float)
    P = P - P.mean(axis=0)
    axis = np.linalg.svd(P, full_matrices=False)[2][-1]
    z = P @ axis
    rho = np.linalg.norm(P - np.outer(z, axis), axis=1)
    R = rho.mean()
    d = np.hypot(rho - R, z)
    r = d.mean()
    return float(R), float(r), float(np.abs(d - r).max() / r) if r > 0 else math.inf


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
    tau : float, optional
        The time step: a round component with less than :data:`EXTINCTION_STEPS`
        of them left is extinct before it collapses (the driver's); without it
        only a collapsed round component is.

    Examples
    --------
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
    >>> F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    >>> check = CollapseCheck(V, F)
    >>> check(V) is None
    True
    >>> print(check(1e-4 * V))
    component 0 of 1 (4 vertices, e.g. vertex 0) shrank to a point: area 2.37e-08 (1e-08 x its initial 2.37), diameter 0.000173 (0.0001 x its initial 1.73)
    >>> check(1e-4 * V).status      # a tetrahedron is not round: q = 0.30
    'degenerated'
    """

    def __init__(self, vertices, faces, *, area_tol=AREA_TOL, diameter_tol=DIAMETER_TOL,
                 measures=None, tau=None):
        V = np.asarray(vertices, dtype=float)
        self.measures = StateMeasures(V, faces) if measures is None else measures
        self.area_tol, self.diameter_tol = float(area_tol), float(diameter_tol)
        self.tau = None if tau is None else float(tau)
        self.count, self.labels = self.measures.count, self.measures.labels
        self._sizes = np.bincount(self.labels, minlength=self.count)
        #: the first point of every component
        self.first = np.unique(self.labels, return_index=True)[1]
        self.chi, self.closed = component_topology(self.measures.faces, self.labels,
                                                   self.count)
        measured = self.measures(V)
        self.renamed(measured.component_area.copy(), measured.diameter.copy(),
                     np.arange(self.count), np.arange(len(V)), self.count)

    def renamed(self, area0, diameter0, ids, vertex_ids, total):
        """The components' initial sizes and their names in the sentences: a check of
        the components that remain of a larger mesh (the driver's, after a component
        vanished) keeps their sizes and names in that mesh.

        Parameters
        ----------
        area0, diameter0 : (count,) float arrays
            Initial area and diameter of every component.
        ids : (count,) int array
            Its number in the larger mesh.
        vertex_ids : (n,) int array
            Every point's number in the larger mesh.
        total : int
            The larger mesh's number of components.
        """
        self.area0, self.diameter0 = np.asarray(area0, float), np.asarray(diameter0, float)
        self.ids, self.vertex_ids, self.total = np.asarray(ids), np.asarray(vertex_ids), total
        # one component of positive size (every surface of the registry): its ratios
        # in Python floats, as numpy divides them, without numpy's per-call overhead
        self._one = (float(self.area0[0]), float(self.diameter0[0])) if self.count == 1 \
            and self.area0[0] > 0 and self.diameter0[0] > 0 else None

    def name(self, c):
        """``"component 1 of 2 (162 vertices, e.g. vertex 162)"``."""
        return (f"component {int(self.ids[c])} of {self.total} ({self._sizes[c]} vertices, "
                f"e.g. vertex {int(self.vertex_ids[self.first[c]])})")

    def __call__(self, vertices, measured=None, t=0.0, final=False):
        """What collapsed or vanished in the state ``vertices`` at time ``t``, a
        :class:`Collapse`, or ``None``; ``measured``: the state's
        :class:`~mcfbench.geometry.measures.Measured` when the caller has it (the
        driver, for both of its checks), else measured here; ``final``: no step
        follows (the run's last state), so a round component is extinct only once
        it collapsed, whatever its time left."""
        V = np.asarray(vertices, dtype=float)
        if measured is None:
            measured = self.measures(V)
        area, diameter = measured.component_area, measured.diameter
        if self._one is not None:
            a, d = float(area[0]), float(diameter[0])
            if math.isfinite(a) and math.isfinite(d) and not (
                    a / self._one[0] < WATCH or d / self._one[1] < self.diameter_tol):
                return None
        if not (np.isfinite(area).all() and np.isfinite(diameter).all()):
            bad = np.flatnonzero(~np.isfinite(V).all(axis=1))
            if len(bad):
                c = int(self.labels[bad[0]])
                return Collapse("degenerated", (
                    f"non-finite coordinates at {len(bad)} vertex(es), e.g. vertex "
                    f"{int(self.vertex_ids[bad[0]])} of component {int(self.ids[c])} of "
                    f"{self.total}"), (c,))
        with np.errstate(divide="ignore", invalid="ignore"):
            a_ratio, d_ratio = area / self.area0, diameter / self.diameter0
        collapsed = (a_ratio < self.area_tol) | (d_ratio < self.diameter_tol)
        watched = np.flatnonzero(collapsed | (a_ratio < WATCH))
        if not len(watched):
            return None
        volume = component_volumes(V, self.measures.faces, self.measures.face_label,
                                   self.count)
        kinds, left = {}, {}
        for c in watched:
            kinds[c], left[c] = self._round(V, int(c), area[c], volume[c])
        extinct = [int(c) for c in watched if kinds[c] is not None and (
            collapsed[c] or (self.tau is not None and not final
                             and left[c] < EXTINCTION_STEPS * self.tau))]
        broken = [int(c) for c in np.flatnonzero(collapsed) if kinds[c] is None]
        if broken:
            c = min(broken, key=lambda k: a_ratio[k])
            shape = "a point" if d_ratio[c] <= POINT * np.sqrt(a_ratio[c]) else "a line"
            more = f" ({int(collapsed.sum())} components collapsed)" \
                if collapsed.sum() > 1 else ""
            return Collapse("degenerated", (
                f"{self.name(c)} shrank to {shape}: area {area[c]:.3g} "
                f"({a_ratio[c]:.3g} x its initial {self.area0[c]:.3g}), diameter "
                f"{diameter[c]:.3g} ({d_ratio[c]:.3g} x its initial {self.diameter0[c]:.3g})"
                + more), (c,), (shape[2:],), (float(area[c]),), (float(volume[c]),),
                (math.nan,))
        if not extinct:
            return None
        times = tuple(float(t) + float(left[c]) for c in extinct)
        detail = "; ".join(
            f"{self.name(c)} vanished round, to a {kinds[c]}: area {area[c]:.3g} "
            f"({a_ratio[c]:.3g} x its initial {self.area0[c]:.3g}), volume {volume[c]:.3g}, "
            f"diameter {diameter[c]:.3g}; extinct at t = {time:.6g} (t = {float(t):.6g} "
            f"and the {left[c]:.3g} a round {kinds[c]} of its size has left)"
            for c, time in zip(extinct, times))
        return Collapse("extinct", detail, tuple(extinct), tuple(kinds[c] for c in extinct),
                        tuple(float(area[c]) for c in extinct),
                        tuple(float(volume[c]) for c in extinct), times)

    def _round(self, V, c, area, volume):
        """``(kind, time left)`` of component ``c`` if it is round (module docstring),
        else ``(None, nan)``."""
        if not (self.closed[c] and area > 0 and volume > 0):
            return None, math.nan
        if self.chi[c] == 2 and 36.0 * math.pi * volume ** 2 / area ** 3 >= ROUND_POINT:
            return "point", area / (16.0 * math.pi)
        if self.chi[c] == 0:
            R, r, spread = tube_fit(V[self.labels == c])
            tube = 2.0 * volume / area
            if spread <= ROUND_TUBE and abs(tube / r - 1.0) <= ROUND_TUBE and r < R:
                return "circle", tube ** 2 / 2.0
            H = np.linalg.norm(mean_curvature_vectors(V, self.measures.faces)[
                self.labels == c], axis=1)
            if np.abs(H * tube - 1.0).max() <= ROUND_TUBE:
                return "curve", tube ** 2 / 2.0
        return None, math.nan
