"""Re-extraction of a surface whose thin parts have reached the mesh's scale: the parts
thinner than the mesh removed through the signed distance where they are about to fold,
the rest kept.

Mean curvature flow takes a thin part of a real shape (a leg, a fin, a thin wall, a
tip) to a singularity long before the body rounds: a tube of radius ``r`` vanishes
at ``t = r^2 / 2``, a sheet's rim of half-thickness ``r`` retreats at speed ``1 / r``.
A mesh of edge ``h`` cannot follow a part thinner than its edge: with the survival
study's step ``tau = 0.1 h^2`` a vertex of mean curvature ``H`` (the sum of the
principal curvatures) moves ``0.1 h^2 H`` in one step, more than the part's
half-thickness ``~1 / H`` once ``H h > 3``, and the part folds (the raw corpus: most
thin-feature meshes end ``inverted`` within 1-7 steps). The level-set flow
(Chen, Giga and Goto 1991; Evans and Spruck 1991) goes on weakly through such a
singularity; the continuation here does what a level-set method at the mesh's scale
does there, and only there: it removes what is thinner than the grid can hold near
the vertices about to fold, and leaves every other part (thin or not) to the flow.

The criterion
-------------
The surface's *sharpness* is ``max H h`` over its vertices of positive angle defect
(a tip, a rim, a convex edge: not a neck, a saddle, which
:mod:`mcfbench.geometry.mesh_surgery` cuts), ``H`` the signed mean curvature
(positive where the surface is convex: ``H = -(Delta X) . n``, the cotangent
Laplacian over the Voronoi mass, ``n`` the outward area-weighted vertex normal),
``h`` the run's resolution (the input's mean edge). The surface is re-extracted when
its sharpness exceeds :data:`SHARPNESS`, or when a neck has pinched (radius below
``h / 2``, :func:`mcfbench.geometry.mesh_surgery.pinched`) that the cut refused (a
handle's neck: the cut must separate). On the dumbbell's level 1 the neck's saddle
reaches ``H h = 4.2`` two steps before its cut at radius ``h / 2``. The *seeds* are
the vertices of ``H h`` above :data:`SHARPNESS` and the uncut neck's ring.

The re-extraction
-----------------
The morphological opening of the enclosed solid ``S`` by a ball of radius
``epsilon = OPENING h`` (Serra 1982): the union of the balls of radius ``epsilon``
inside ``S``, ``O = {x : dist(x, S_-) < epsilon}`` with ``S_- = {d < -epsilon}`` the
solid eroded by ``epsilon`` (``d`` libigl's signed distance to the surface, negative
inside, its sign the winding number's). A part thinner than ``2 epsilon`` vanishes, a
convex edge or tip is rounded to radius ``epsilon``, and every part of the surface
whose inside contains a ball of radius ``epsilon`` touching it is left where it was
(concave parts and every part of curvature below ``1 / epsilon``). The opening is
applied only within ``rho = REACH h`` of the seeds (:data:`REACH`): the new solid is
``S`` outside that region and ``O`` in it, ``S ∩ (O ∪ {dist(x, seeds) > rho})``, the
zero set of ``max(d, min(d_O, rho - dist(x, seeds)))`` (``d_O = d_{S_-} - epsilon``
the opening's; written with the signs flipped, positive inside, for marching cubes):
a thin part is cut where it leaves the region, and the thin parts elsewhere (a leg, a
rod, a handle not yet about to fold) stay for the flow to thin. The surfaces
(``S_-``'s and the result's) are extracted by marching cubes
(:func:`mcfbench.geometry.implicit.isosurface`, scikit-image's) on a grid of spacing
``GRID h`` padded by ``epsilon`` and two cells, the distances libigl's
(``igl.signed_distance``, exact to the triangles); outside the region the result is
the surface re-extracted on the grid, within its ``O(GRID^2 h^2)`` of the input.
The components of the result thinner than the opening everywhere are removed with
it (:func:`without_fragments`: the pieces of a thin part that the opening cut on both
sides, marching cubes' bubbles of a part thinner than its grid). The caller remeshes
the result to the run's edge (:func:`mcfbench.geometry.remeshing.remesh`). An
opening that would leave nothing (no point of the solid deeper than ``epsilon``) is
refused: the flow takes a surface thinner than the mesh everywhere to its own
extinction (round:
``extinct``, a point, a circle or a curve: :mod:`mcfbench.geometry.collapse`; the raw
corpus's CAD tubes vanish round to a circle within 1-2 steps).

The area removed
----------------
What the opening took, not the grid's error: the area of the input's triangles whose
centroid lies more than half a grid cell (``GRID h / 2``) outside the result, minus
that of the result's triangles more than half a cell inside the input
(:func:`area_off`; libigl's signed distance). The re-extraction moves the rest of
the surface by much less than that (the test's barbell: 0.05 h at most), so its area
change (marching cubes' chords lose 1-5 % of a coarse surface's area) is not counted
as removed; a thin part's foot, within half a cell of the result, is not either (its
area ``2 pi r GRID h / 2`` for a tube of radius ``r``). The volume removed is the
volume before minus after.
"""

from typing import NamedTuple

import numpy as np

from mcfbench.geometry import metrics
from mcfbench.geometry.collapse import mean_curvature_vectors
from mcfbench.geometry.measures import vertex_components

SHARPNESS = 3.0
"""A surface whose ``max H h`` exceeds this is re-extracted (module docstring)."""

OPENING = 1.0
"""The opening's radius in units of ``h``."""

GRID = 0.5
"""The marching cubes' grid spacing in units of ``h``."""

REACH = 2.0
"""The opening changes the solid only within this many ``h`` of the seeds (module
docstring): twice the opening, so that a tip's or a rim's part thinner than ``2 h``
goes within one step and the cut it leaves is at least ``h`` from the seeds."""


MAX_GRID_POINTS = 1_000_000
"""The most grid points one extraction samples (a mesh whose box holds more at
``GRID h`` is refused: the signed distance would take minutes)."""


class Reextraction(NamedTuple):
    """What :func:`open_surface` did.

    Attributes
    ----------
    vertices : (n', 3) float array
    faces : (m', 3) int array
        The opened surface, outward oriented.
    where : (3,) float array
        The sharpest vertex's position.
    sharpness : float
        ``max H h`` before.
    components_before, components_after : int
    area_removed, volume_removed : float
        The area the opening took (module docstring: not the grid's error); the
        volume before minus after.
    """

    vertices: np.ndarray
    faces: np.ndarray
    where: np.ndarray
    sharpness: float
    components_before: int
    components_after: int
    area_removed: float
    volume_removed: float


def signed_mean_curvature(vertices, faces, vectors=None):
    """``H = -(Delta X) . n`` at every vertex (module docstring): ``2 / R`` on a sphere
    of radius ``R`` with outward triangles, negative at a concave vertex.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    vectors : (n, 3) float array, optional
        The mesh's ``H n`` (:func:`mcfbench.geometry.mesh_surgery.mean_curvature_vectors`)
        when computed already.

    Returns
    -------
    (n,) float array
    """
    import igl  # on first use


    V, F = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    normals = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    vectors = mean_curvature_vectors(V, F) if vectors is None else vectors
    return -np.einsum("ij,ij->i", vectors, normals)


def convex_sharpness(vertices, faces, h, known=None):
    """``H h`` at every vertex of positive angle defect, ``-inf`` at the others (module
    docstring); ``known`` the mesh's :func:`mcfbench.geometry.mesh_surgery.curvature`
    when computed already.

    Returns
    -------
    (n,) float array
    """
    from mcfbench.geometry.mesh_surgery import curvature

    vectors, defects = curvature(vertices, faces) if known is None else known
    H = signed_mean_curvature(vertices, faces, vectors) * h
    return np.where(np.isfinite(H) & (defects > 0), H, -np.inf)


def sharpness(vertices, faces, h, known=None):
    """``(max H h, the vertex where it is)`` over the vertices of positive angle defect
    (module docstring), ``(-inf, 0)`` without one; ``known`` as :func:`convex_sharpness`'s."""
    H = convex_sharpness(vertices, faces, h, known)
    v = int(np.argmax(H))
    return float(H[v]), v


def open_surface(vertices, faces, h, *, necks=(), opening=OPENING, grid=GRID,
                 reach=REACH):
    """The solid of a closed, outward-oriented mesh opened by a ball of radius
    ``opening h`` within ``reach h`` of its sharp vertices and of ``necks``, and kept
    elsewhere (module docstring).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    h : float
        The run's resolution.
    necks : (k, 3) float array
        Points of pinched necks that were not cut (the module docstring's seeds with
        the sharp vertices).
    opening, grid, reach : float
        In units of ``h``.

    Returns
    -------
    surgery : Reextraction or None
    reason : str
        Why there is none (empty when there is one): an open mesh (its inside is not
        defined), a box too large for the grid, marching cubes' failure, or the whole
        surface thinner than the opening.
    """
    import igl  # on first use
    from scipy.spatial import cKDTree

    from mcfbench.geometry.implicit import isosurface
    from mcfbench.geometry.remeshing import boundary_vertices

    V, F = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    if len(boundary_vertices(F)):
        return None, "the mesh is open: its inside, and so its opening, is not defined"
    eps, spacing = opening * h, grid * h
    lower = V.min(axis=0) - eps - 2 * spacing
    upper = V.max(axis=0) + eps + 2 * spacing
    cells = np.ceil((upper - lower) / spacing) + 1
    if np.prod(cells) > MAX_GRID_POINTS:
        return None, (f"the grid of spacing {spacing:.3g} over the mesh's box has "
                      f"{int(np.prod(cells)):,} points, more than {MAX_GRID_POINTS:,}")
    resolution = int(cells.max())
    H = convex_sharpness(V, F, h)
    v = int(np.argmax(H))
    necks = np.asarray(necks, dtype=float).reshape(-1, 3)
    seeds = np.vstack([V[H > SHARPNESS], necks])
    where = V[v] if H[v] > SHARPNESS or not len(necks) else necks[0]
    before = vertex_components(F, len(V))[0]
    volume0 = metrics.volume(V, F)
    depth = {}                      # -d on the grid, sampled once for both extractions

    def inside(x, y, z):
        if "grid" not in depth:
            points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
            depth["grid"] = -igl.signed_distance(points, V, F)[0].reshape(x.shape)
        return depth["grid"]

    try:
        eroded = isosurface(lambda x, y, z: inside(x, y, z) - eps, lower, upper, resolution)
    except ValueError as err:
        if "level must be within" not in str(err):
            return None, f"marching cubes of the eroded solid: {err}"
        return None, ("the whole surface is thinner than the opening: left to the flow, "
                      "which takes it to its extinction")

    def local(x, y, z):
        """``min(-d, max(epsilon - d_E, dist(x, seeds) - reach h))`` (module docstring),
        ``d_E`` the signed distance to the eroded surface, asked only near the seeds."""
        points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
        away = (cKDTree(seeds).query(points)[0] if len(seeds)
                else np.full(len(points), np.inf)) - reach * h
        opened = np.full(len(points), -np.inf)
        near = away < 2 * spacing       # beyond, the opening cannot change the sign
        if near.any():
            opened[near] = eps - igl.signed_distance(points[near], *eroded)[0]
        return np.minimum(inside(x, y, z), np.maximum(opened, away).reshape(x.shape))

    try:
        U, G = isosurface(local, lower, upper, resolution)
    except ValueError as err:
        return None, f"marching cubes of the locally opened solid: {err}"
    U, G = without_fragments(U, G, eroded[0])
    after = vertex_components(G, len(U))[0]
    return Reextraction(U, G, where.copy(), float(H[v]), int(before), int(after),
                        area_off((V, F), (U, G), spacing / 2)
                        - area_off((U, G), (V, F), spacing / 2, inside=True),
                        float(volume0 - metrics.volume(U, G))), ""


def without_fragments(vertices, faces, deep):
    """The surface without its fragments: the components that hold none of the points
    ``deep`` (the eroded solid's surface), thinner than the opening everywhere, which
    the flow would take away within ``h^2 / 2``: a piece of a thin part between two of
    the opening's cuts, or a bubble that marching cubes leaves of a part thinner than
    its grid (the raw fox's, at step 0: 4 vertices, degenerate a step later).

    A point inside one of several disjoint, non-nested closed components is nearer to
    that component's surface than to any other's (the segment to another crosses its
    own first): each point of ``deep`` is in the component of its nearest triangle
    (libigl's ``point_mesh_squared_distance``).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    deep : (k, 3) float array

    Returns
    -------
    vertices : (n', 3) float array
    faces : (m', 3) int array
    """
    import igl  # on first use

    U, G = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    count, labels = vertex_components(G, len(U))
    if count == 1:
        return U, G
    held = np.zeros(count, bool)
    held[labels[G[igl.point_mesh_squared_distance(np.asarray(deep, float), U, G)[1], 0]]] \
        = True
    keep = held[labels]
    number = np.cumsum(keep) - 1
    return U[keep], number[G[keep[G[:, 0]]]]


def area_off(surface, other, tolerance, inside=False):
    """The area of the triangles of ``surface`` whose centroid is more than
    ``tolerance`` outside (``inside``: inside) the closed surface ``other`` (libigl's
    signed distance; module docstring).

    Parameters
    ----------
    surface, other : tuple of ((n, 3) float array, (m, 3) int array)
    tolerance : float
    inside : bool

    Returns
    -------
    float
    """
    import igl  # on first use

    (V, F), (U, G) = surface, other
    distance = igl.signed_distance(V[F].mean(axis=1), U, G)[0]
    off = distance < -tolerance if inside else distance > tolerance
    return float(metrics.triangle_areas(V, F)[off].sum())
