"""Thin features of a surface at its mesh's scale, decided from the mesh alone.

A part of a surface is *thin* where the surface, seen from inside, comes
back within two mean edges: a ray cast from a triangle's centroid along its
inward normal meets the surface again at a distance below ``2 h``, with
``h`` the mean edge length. A mean curvature flow pinches such a part at the
scale of the mesh (a tube of radius ``r`` vanishes at ``t = r^2 / 2``), so a
scheme that folds there may be meeting the flow's own singularity, not a
defect of its own (issue #44: remeshing did not help on the animals' fins and
legs). The criterion is the local feature size of the brief (the distance
across the inside compared with ``2 h``), measured by one ray per triangle:

* ``thickness(t)`` = distance from the centroid of triangle ``t`` to the first
  triangle hit by the ray along ``-n_t`` (``n_t`` its unit normal, outward
  when the enclosed signed volume is positive; otherwise the normals are
  reversed first, so an inward-oriented file is measured from its inside);
  ``inf`` when the ray leaves the surface (open surfaces, a ray through a
  hole). libigl's AABB tree casts the rays (``igl.AABB.intersect_ray_first``,
  in single precision: a distance to about ``1e-6`` of the mesh's size).
* ``thin_share`` = area of the triangles with ``thickness < 2 h`` over the
  total area;
* a mesh **has thin features** when ``thin_share > THIN_SHARE`` (2 % of its
  area).

Triangles rather than vertices: a triangle's normal and area are exact (a
vertex normal is a weighted average) and the share of area is a sum of
triangle areas. The share was fixed before any scheme ran on the raw corpus
(``mcfbench/data/raw_meshes/``), and its value and verdict per mesh are
committed in its manifest.
"""

from dataclasses import dataclass

import igl
import numpy as np

from mcfbench.geometry.metrics import mean_edge_length, triangle_areas, volume

THICKNESS_FACTOR = 2.0
"""A part is thin where it is thinner than this many mean edges."""

THIN_SHARE = 0.02
"""A mesh has thin features when more than this share of its area is thin."""


@dataclass(frozen=True)
class ThinFeatures:
    """The thin-feature criterion's value on one mesh (see the module docstring).

    Attributes
    ----------
    mean_edge : float
        ``h``, each edge once.
    thin_share : float
        Share of the area thinner than ``THICKNESS_FACTOR * h``, in ``[0, 1]``.
    thin : bool
        ``thin_share > THIN_SHARE``.
    """

    mean_edge: float
    thin_share: float

    @property
    def thin(self):
        return bool(self.thin_share > THIN_SHARE)


def triangle_thickness(vertices, faces):
    """Distance across the inside from each triangle's centroid along its
    inward normal to the next triangle met (``inf`` if none).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
        A valid surface (:func:`mcfbench.geometry.mesh.validate_mesh`).

    Returns
    -------
    (m,) float64 array
    """
    V = np.ascontiguousarray(vertices, dtype=np.float64)
    F = np.ascontiguousarray(faces, dtype=np.int64)
    P = V[F]
    centroid = P.mean(axis=1)
    normal = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    normal /= np.linalg.norm(normal, axis=1)[:, None]
    if volume(V, F) < 0:
        normal = -normal
    # start a hair inside the triangle's plane, so the ray does not meet its own
    # triangle: libigl intersects in single precision, so the hair is 1e-6 of the
    # mesh's size (16 float32 roundings), and the distances are as accurate
    eps = 1e-6 * float(np.ptp(V, axis=0).max())
    tree = igl.AABB()
    tree.init(V, F)
    hit, t, _ = tree.intersect_ray_first(V, F, centroid - eps * normal, -normal)
    return np.where(hit >= 0, np.asarray(t) + eps, np.inf)


def thin_features(vertices, faces):
    """The thin-feature criterion of the module docstring on ``(vertices, faces)``.

    Returns
    -------
    ThinFeatures
    """
    h = mean_edge_length(vertices, faces)
    area = triangle_areas(vertices, faces)
    thin = triangle_thickness(vertices, faces) < THICKNESS_FACTOR * h
    return ThinFeatures(mean_edge=float(h), thin_share=float(area[thin].sum() / area.sum()))
