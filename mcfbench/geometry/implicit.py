"""Surfaces extracted by marching cubes from an implicit function: metaballs (blobby) and a
tilted torus, the real-world-like meshes of the matrix."""

import numpy as np

from mcfbench.geometry.construction import (
    check_closed_manifold,
    rotation,
    weld_vertices,
)


def isosurface(field, lower, upper, resolution, weld=1e-3):
    """Closed triangle mesh of ``{field > 0}`` by marching cubes, cleaned.

    ``field`` is sampled on the grid of spacing ``d = max(upper - lower) /
    (resolution - 1)`` covering the box ``[lower, upper]`` and triangulated
    by :func:`skimage.measure.marching_cubes` (Lewiner et al., J. Graphics
    Tools 8 (2003), level 0). Marching cubes puts vertices almost on top of
    each other where the surface passes near a grid node (triangle areas
    down to ``1e-10`` of the mean), so each cluster of vertices closer than
    ``weld * d`` (coincident ones always) is merged into its first vertex,
    placed at the cluster's mean. Then triangles repeating a vertex or of
    zero area are removed, so are pairs of triangles on the same three
    vertices (a fold) and unreferenced vertices. The valences stay
    irregular and slivers remain (smallest area ~1e-6 of the mean, angles
    below 0.1 degree), as in scanned meshes. Over 36 meshes tried
    (resolutions 20-88, :func:`blobby` and :func:`implicit_torus`) the
    default weld folded no triangle; welds of ``3e-3`` and more sometimes
    fold a sliver (see :func:`mcfbench.geometry.metrics.flipped_triangles`).

    Parameters
    ----------
    field : callable
        ``field(x, y, z)`` of broadcast arrays, positive inside, negative
        outside and on the faces of the box.
    lower, upper : (3,) array_like
        Corners of the box.
    resolution : int
        Grid points along the longest side, ``>= 8``.
    weld : float
        Merge distance in units of ``d``, ``in [0, 0.1]`` (0: coincident
        vertices only).

    Returns
    -------
    vertices : (n, 3) float array
    faces : (m, 3) int64 array
        Normals pointing out of ``{field > 0}``.

    Raises
    ------
    ValueError
        If the cleaned mesh is not a closed 2-manifold (every edge in
        exactly two triangles traversing it in opposite directions, the
        triangles at every vertex forming one fan): surface leaving the
        box, too coarse a grid, or a weld that pinched the surface.
    """
    from skimage.measure import marching_cubes

    if resolution < 8:
        raise ValueError(f"resolution must be at least 8, got {resolution}")
    if not 0 <= weld <= 0.1:
        raise ValueError(f"weld must lie in [0, 0.1], got {weld!r}")
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    d = (upper - lower).max() / (int(resolution) - 1)
    axes = [lower[i] + d * np.arange(int(np.ceil((upper[i] - lower[i]) / d - 1e-9)) + 1)
            for i in range(3)]
    values = field(*np.meshgrid(*axes, indexing="ij"))
    # field > 0 inside: "ascent" orients the triangles with outward normals
    V, F, _, _ = marching_cubes(values, 0.0, spacing=(d, d, d), gradient_direction="ascent")
    V, F = weld_vertices(V.astype(np.float64) + lower, F.astype(np.int64), weld * d)
    check_closed_manifold(V, F)
    return V, F


_BLOBS = np.array([  # centre x, y, z, Gaussian width, weight
    [0.0, 0.0, 0.0, 0.55, 1.0],
    [0.75, 0.2, 0.1, 0.4, 0.8],
    [-0.45, 0.55, -0.2, 0.4, 0.8],
    [-0.2, -0.6, 0.4, 0.35, 0.7],
    [0.25, -0.1, -0.7, 0.35, 0.7],
])


def metaballs(x, y, z):
    """Metaball field ``sum_i w_i exp(-|x - c_i|^2 / (2 s_i^2)) - 1/2`` of :func:`blobby`.

    Parameters
    ----------
    x, y, z : arrays of one shape

    Returns
    -------
    array of that shape
    """
    c, s, w = _BLOBS[:, :3], _BLOBS[:, 3], _BLOBS[:, 4]
    d2 = ((x[..., None] - c[:, 0]) ** 2 + (y[..., None] - c[:, 1]) ** 2
          + (z[..., None] - c[:, 2]) ** 2)
    return (w * np.exp(-d2 / (2.0 * s**2))).sum(axis=-1) - 0.5


def blobby(resolution=40):
    """Genus-0 blob: five Gaussian metaballs (:func:`metaballs`) meshed by marching cubes.

    Box ``[-1.6, 1.6]^3``; grid spacing ``3.2 / (resolution - 1)``
    (:func:`isosurface`). A smooth, non-convex, non-symmetric surface
    meshed irregularly.

    Parameters
    ----------
    resolution : int
        Grid points per side (40: ``n_F = 2646``, ``n_T = 5288``).

    Returns
    -------
    vertices : (n, 3) float array
    faces : (2 n - 4, 3) int64 array
    """
    return isosurface(metaballs, [-1.6] * 3, [1.6] * 3, resolution)


_TORUS_TILT = rotation(0.4, 0.25, 0.1)


def implicit_torus(resolution=48, R=1.0, r=0.35):
    """Torus of radii ``R, r``, tilted off the grid axes, by marching cubes (genus 1).

    The level set ``r^2 - (sqrt(p_x^2 + p_y^2) - R)^2 - p_z^2 = 0`` with
    ``p = Q^T x``, ``Q`` a fixed rotation (so that the torus does not line
    up with the grid), in the box ``[-1.6, 1.6]^3`` (:func:`isosurface`).
    Enclosed volume ``2 pi^2 R r^2``, area ``4 pi^2 R r``.

    Parameters
    ----------
    resolution : int
        Grid points per side (48: ``n_F = 4476``, ``n_T = 8952``).
    R, r : float
        ``R + r < 1.5``, ``r > 0``.

    Returns
    -------
    vertices : (n, 3) float array
    faces : (2 n, 3) int64 array
    """
    if not (0 < r < R and R + r < 1.5):
        raise ValueError(f"need 0 < r < R and R + r < 1.5, got R = {R!r}, r = {r!r}")
    Q = _TORUS_TILT

    def field(x, y, z):
        px = Q[0, 0] * x + Q[1, 0] * y + Q[2, 0] * z
        py = Q[0, 1] * x + Q[1, 1] * y + Q[2, 1] * z
        pz = Q[0, 2] * x + Q[1, 2] * y + Q[2, 2] * z
        return r**2 - (np.hypot(px, py) - R) ** 2 - pz**2

    return isosurface(field, [-1.6] * 3, [1.6] * 3, resolution)
