"""Isotropic remeshing of a surface mid-flow, when to do it, and what it changed.

:func:`remesh` is Botsch and Kobbelt's isotropic remeshing (M. Botsch, L. Kobbelt,
"A remeshing approach to multiresolution modeling", SGP 2004, section 4): split the
edges longer than ``4/3 h``, collapse those shorter than ``4/5 h``, flip edges toward
valence 6 (4 on the boundary), relax every vertex tangentially toward its
neighbours' centroid, and project it back onto the input surface; repeated
``passes`` times. It is gpytoolbox's compiled implementation
(``gpytoolbox.remesh_botsch(V, F, i, h, project=True)``), the input's boundary
vertices held as feature vertices (a Dirichlet boundary stays where it was, vertex
for vertex). The projection is onto the current, piecewise linear surface: a
smooth surface's remeshed vertices lie within ``O(h^2)`` of it (a triangle's
distance to its circumscribed surface), which :func:`remesh_change` measures.

**Target length.** ``h = sqrt(2 A / (sqrt(3) n))`` (:func:`target_edge`): the edge of
``n`` equilateral triangles' vertices covering the area ``A`` (``2n`` triangles of
area ``sqrt(3) h^2 / 4`` on a closed surface), so the vertex count stays the input's.
It is the input's mean edge on a uniform mesh; on the anisotropic sphere (edges
4:1) the mean edge would drop the count from 1 922 to 734 vertices.

**When** (:class:`RemeshTrigger`): the smallest angle of the mesh below
``angle`` degrees (a sliver before it folds), or a fixed interval of *time*
``every`` (not of steps: with ``tau ~ h^2``, a remesh every ``k`` steps is
``O(h^-2)`` remeshes whose ``O(h^2)`` projection errors add up to ``O(1)``).
A remesh that could not lift the smallest angle to ``angle`` (the boundary's
vertices are held, so a sliver on the boundary stays; a folded input stays folded)
is not repeated until the smallest angle has fallen to :data:`RELAPSE` times what
that remesh left: otherwise every step remeshes, each adding its projection error
for no gain (on the raw corpus's flat strip ``narrow_triangles``, smallest angle
0.03 degrees on its boundary: 37 remeshes in 37 steps, then a fold, where the
schemes without remeshing reach the end).

**What the compiled remesher is given** (:func:`remesh`). gpytoolbox's binding
builds a half-edge structure and has no checks of its own beyond non-manifold
edges: a non-finite coordinate, a non-manifold vertex, a duplicate or zero-area
triangle or an unreferenced vertex can crash the process (two crashes, SIGSEGV and
SIGABRT, in a survival pass). The input is checked first, by the intake's own
:func:`mcfbench.geometry.mesh.validate_mesh`, and so is the output, and the arrays
are passed as the binding wants them (contiguous ``float64`` and ``int32``); a
bad one raises :class:`RemeshRefused` naming the problem, which the run reports
(the driver ends it ``degenerated`` with that sentence) instead of a dead batch.
Checking rather than isolating each call in a child process: a check costs
milliseconds against a child's start and the copying of the mesh both ways, and
it names the defect, where a crashed child only says that it died.
"""

import math

import numpy as np

from mcfbench.geometry import metrics
from mcfbench.geometry.collapse import component_topology
from mcfbench.geometry.measures import vertex_components
from mcfbench.geometry.mesh import MeshError, validate_mesh
from mcfbench.geometry.surface_distance import mean_surface_distance

PASSES = 3
"""Passes of split, collapse, flip and relaxation per remesh (Botsch and Kobbelt use
5-10 from scratch; mid-flow the mesh is near the target already: 3 raise the
anisotropic sphere's smallest angle from 2.8 to 19 degrees)."""

ANGLE = 10.0
"""Degrees: a mesh whose smallest angle is below this is remeshed (a fresh remesh
has its smallest angle at 20-35 degrees; the registry's meshes start above 10
except the slivered ones: the anisotropic sphere 2.8)."""


RELAPSE = 0.5
"""After a remesh that left the smallest angle below the trigger's ``angle``, the next
quality remesh waits until the smallest angle is below this share of what it left
(module docstring)."""


def target_edge(vertices, faces):
    """The edge length that keeps the vertex count: ``sqrt(2 A / (sqrt(3) n))``
    (module docstring), ``A`` the area, ``n`` the vertex count."""
    return math.sqrt(2.0 * metrics.area(vertices, faces) / (math.sqrt(3.0) * len(vertices)))


def boundary_vertices(faces):
    """(b,) int array: the vertices on an edge of one triangle, sorted."""
    F = np.asarray(faces, dtype=np.int64)
    edges, seen = np.unique(np.sort(F[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1),
                            axis=0, return_counts=True)
    return np.unique(edges[seen == 1])


class RemeshRefused(ValueError):
    """The remesher's input or output is not a valid surface (module docstring: what
    the compiled remesher is given); the message names the problem."""


def remesh(vertices, faces, h, passes=PASSES):
    """The surface ``(vertices, faces)`` remeshed to edge length ``h`` (module docstring).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    h : float
    passes : int

    Returns
    -------
    vertices : (n', 3) float array
        The boundary vertices first, in their input order, at their input positions.
    faces : (m', 3) int array

    Raises
    ------
    RemeshRefused
        The input is not a valid surface (:func:`~mcfbench.geometry.mesh.validate_mesh`:
        non-finite coordinates, a repeated, duplicate or zero-area triangle, an
        unreferenced vertex, a non-manifold edge or vertex, ...), ``h`` is not a
        positive number or ``passes`` not a whole number >= 1, or the output is not
        a valid surface; the compiled remesher is not called on a bad input.
    """
    if not (np.isfinite(h) and h > 0) or int(passes) != passes or passes < 1:
        raise RemeshRefused(f"the remesher needs an edge length > 0 and whole passes >= 1, "
                            f"got h={h!r}, passes={passes!r}")
    try:
        V, F = validate_mesh(vertices, faces)
    except MeshError as err:
        raise RemeshRefused(f"the remesher refused its input ({err.kind}): {err}") from None
    import gpytoolbox  # on first use: the flows that never remesh do not load it

    V = np.ascontiguousarray(V, dtype=np.float64)
    F = np.ascontiguousarray(F, dtype=np.int32)
    fixed = np.ascontiguousarray(boundary_vertices(F), dtype=np.int32)
    U, G = gpytoolbox.remesh_botsch(V, F, int(passes), float(h), True, feature=fixed)
    try:
        U, G = validate_mesh(U, G)
    except MeshError as err:
        raise RemeshRefused(f"the remesher's output is not a valid surface ({err.kind}): "
                            f"{err}") from None
    return np.ascontiguousarray(U, dtype=float), np.ascontiguousarray(G, dtype=np.int64)


def topology(vertices, faces):
    """``(components, Euler characteristics)`` of a mesh: the count and the sorted
    tuple of every component's ``chi``."""
    count, labels = vertex_components(faces, len(vertices))
    chi, _ = component_topology(faces, labels, count)
    return count, tuple(sorted(int(c) for c in chi))


def remesh_change(before, after):
    """What a remesh changed: the fields of the run's ``remeshed`` event.

    Parameters
    ----------
    before, after : tuple of ((n, 3) float array, (m, 3) int array)
        The surface before and after.

    Returns
    -------
    dict
        ``distance`` (:func:`~mcfbench.geometry.surface_distance.mean_surface_distance`),
        ``area_change`` and ``volume_change`` (after minus before),
        ``vertices_before``, ``vertices_after``, ``min_angle_before``,
        ``min_angle_after`` (degrees), and ``topology_changed`` (the components'
        count or Euler characteristics differ) with ``topology_before``,
        ``topology_after``.
    """
    (V0, F0), (V1, F1) = before, after
    top0, top1 = topology(V0, F0), topology(V1, F1)
    return {"distance": mean_surface_distance(V0, F0, V1, F1),
            "area_change": metrics.area(V1, F1) - metrics.area(V0, F0),
            "volume_change": metrics.volume(V1, F1) - metrics.volume(V0, F0),
            "vertices_before": len(V0), "vertices_after": len(V1),
            "min_angle_before": metrics.min_angle(V0, F0),
            "min_angle_after": metrics.min_angle(V1, F1),
            "topology_changed": top0 != top1,
            "topology_before": [top0[0], list(top0[1])],
            "topology_after": [top1[0], list(top1[1])]}


class RemeshTrigger:
    """When a run remeshes: the smallest angle below ``angle`` degrees (or below
    :data:`RELAPSE` times what the last remesh left, when that was below ``angle``),
    or ``every`` time units since the last remesh (module docstring).

    Parameters
    ----------
    angle : float
        Degrees; 0 turns the quality trigger off.
    every : float or None
        Time between remeshes; None turns the time trigger off.
    """

    def __init__(self, angle=ANGLE, every=None):
        if not angle >= 0 or every is not None and not every > 0:
            raise ValueError(f"a remesh trigger needs angle >= 0 and every > 0 or None, got "
                             f"angle={angle!r}, every={every!r}")
        self.angle, self.every, self.last = float(angle), every, 0.0
        self.threshold = self.angle

    def __call__(self, vertices, faces, t):
        """Why the state at time ``t`` is to be remeshed (a sentence), or None."""
        if self.every is not None and t - self.last >= self.every * (1 - 1e-9):
            return f"{t - self.last:.4g} time units since the last remesh"
        if self.threshold > 0:
            smallest = metrics.min_angle(vertices, faces)
            if smallest < self.threshold:
                return f"smallest angle {smallest:.3g} degrees < {self.threshold:.3g}"
        return None

    def done(self, t, min_angle=None):
        """A remesh happened at time ``t``, leaving the smallest angle ``min_angle``
        degrees (None: not known, the threshold stays ``angle``)."""
        self.last = t
        self.threshold = self.angle if min_angle is None or min_angle >= self.angle \
            else RELAPSE * float(min_angle)
