"""Re-extraction of a surface whose thin parts have reached the mesh's scale: the parts
thinner than the mesh removed through the signed distance, the rest kept.

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
does there: it removes what is thinner than the grid can hold.

The criterion
-------------
The surface's *sharpness* is ``max H h`` over its vertices of positive angle defect
(a tip, a rim, a convex edge: not a neck, a saddle, which
:mod:`mcfbench.geometry.mesh_surgery` cuts), ``H`` the signed mean curvature
(positive where the surface is convex: ``H = -(Delta X) . n``, the cotangent
Laplacian over the Voronoi mass, ``n`` the outward area-weighted vertex normal),
``h`` the run's resolution (the input's mean edge). The surface is re-extracted when
its sharpness exceeds :data:`SHARPNESS`. On the dumbbell's level 1 the neck's
saddle reaches ``H h = 4.2`` two steps before its cut at radius ``h / 2``.

The re-extraction
-----------------
The morphological opening of the enclosed solid ``S`` by a ball of radius
``epsilon = OPENING h``: the union of the balls of radius ``epsilon`` inside ``S``,
``{x : dist(x, S_-) < epsilon}`` with ``S_- = {d < -epsilon}`` the solid eroded by
``epsilon`` (``d`` libigl's signed distance to the surface, negative inside, its sign
the winding number's). A part thinner than ``2 epsilon`` vanishes, a convex edge or
tip is rounded to radius ``epsilon``, and every part of the surface whose inside
contains a ball of radius ``epsilon`` touching it is left where it was (concave parts
and every part of curvature below ``1 / epsilon``): after it the convex principal
curvatures are at most ``1 / epsilon``, its sharpness at most ``2 / OPENING`` below
:data:`SHARPNESS`. Both surfaces (``S_-``'s and the opening's) are extracted by
marching cubes (:func:`mcfbench.geometry.implicit.isosurface`, scikit-image's) on a
grid of spacing ``GRID h`` padded by ``epsilon`` and two cells, the distances
libigl's (``igl.signed_distance``, exact to the triangles); the caller remeshes the
result to the run's edge (:func:`mcfbench.geometry.remeshing.remesh`). A component
thinner than the opening everywhere is removed with the rest when another remains (it
would vanish within ``h^2 / 2``); an opening that would leave nothing is refused: the
flow takes a surface thinner than the mesh everywhere to its own extinction (round:
``extinct``; the raw corpus's CAD tubes vanish round to a circle within 1-2 steps).
"""

from typing import NamedTuple

import numpy as np

from mcfbench.geometry import metrics
from mcfbench.geometry.measures import vertex_components

SHARPNESS = 3.0
"""A surface whose ``max H h`` exceeds this is re-extracted (module docstring)."""

OPENING = 1.0
"""The opening's radius in units of ``h``."""

GRID = 0.5
"""The marching cubes' grid spacing in units of ``h``."""

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
        Before minus after.
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

    from mcfbench.geometry.mesh_surgery import mean_curvature_vectors

    V, F = np.asarray(vertices, dtype=float), np.asarray(faces, dtype=np.int64)
    normals = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    vectors = mean_curvature_vectors(V, F) if vectors is None else vectors
    return -np.einsum("ij,ij->i", vectors, normals)


def sharpness(vertices, faces, h, known=None):
    """``(max H h, the vertex where it is)`` over the vertices of positive angle defect
    (module docstring), ``(-inf, 0)`` without one; ``known`` the mesh's
    :func:`mcfbench.geometry.mesh_surgery.curvature` when computed already."""
    from mcfbench.geometry.mesh_surgery import curvature

    vectors, defects = curvature(vertices, faces) if known is None else known
    H = signed_mean_curvature(vertices, faces, vectors)
    H = np.where(np.isfinite(H) & (defects > 0), H, -np.inf)
    v = int(np.argmax(H))
    return float(H[v] * h), v


def open_surface(vertices, faces, h, *, opening=OPENING, grid=GRID):
    """The opening of the solid of a closed, outward-oriented mesh by a ball of radius
    ``opening h`` (module docstring).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    h : float
        The run's resolution.
    opening, grid : float
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
    sharp, v = sharpness(V, F, h)
    before = vertex_components(F, len(V))[0]
    area0, volume0 = metrics.area(V, F), metrics.volume(V, F)

    def distance(x, y, z, to):
        points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
        return igl.signed_distance(points, *to)[0].reshape(x.shape)

    empty = np.empty((0, 3)), np.empty((0, 3), dtype=np.int64)
    try:
        eroded = isosurface(lambda x, y, z: -distance(x, y, z, to=(V, F)) - eps,
                            lower, upper, resolution)
    except ValueError as err:
        if "level must be within" not in str(err):
            return None, f"marching cubes of the eroded solid: {err}"
        eroded = None                       # nothing is thicker than 2 epsilon
    if eroded is None:
        U, G = empty
    else:
        try:
            U, G = isosurface(lambda x, y, z: eps - distance(x, y, z, to=eroded),
                              lower, upper, resolution)
        except ValueError as err:
            return None, f"marching cubes of the opened solid: {err}"
    if not len(G):
        return None, ("the whole surface is thinner than the opening: left to the flow, "
                      "which takes it to its extinction")
    after = vertex_components(G, len(U))[0]
    area1, volume1 = metrics.area(U, G), metrics.volume(U, G)
    return Reextraction(U, G, V[v].copy(), sharp, int(before), int(after),
                        float(area0 - area1), float(volume0 - volume1)), ""

