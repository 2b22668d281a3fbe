"""Distance between two triangulated surfaces: the symmetric mean surface
distance, area-weighted, through libigl's exact point-to-mesh distance.

For surfaces ``A`` and ``B`` with areas ``|A|``, ``|B|`` and
``d(x, S) = min_{y in S} |x - y|``,

    D(A, B) = ( int_A d(x, B) dA(x) + int_B d(y, A) dA(y) ) / (|A| + |B|),

the mean of the point-to-surface distances both ways, each point weighted
by the area it stands for (the "average symmetric surface distance" of
image segmentation, e.g. Heimann et al., IEEE TMI 28 (2009), 1251-1265,
there over voxel surfaces). ``D`` is symmetric, zero for a surface against
itself, invariant under rigid motions of both, and ``D = |r_1 - r_2|``
for concentric spheres of radii ``r_1``, ``r_2``: it measures how far apart
two approximations of one flowed surface lie, whatever their meshes.

Discretisation: each integral by the vertex (lumped-mass) quadrature
``int_A f dA ~ sum_i m_i f(x_i)``, ``m_i`` a third of the area of the
triangles at vertex ``i`` (:func:`mcfbench.geometry.metrics.lumped_mass`),
and ``d(x_i, B)`` exact to the triangles of ``B``
(``igl.point_mesh_squared_distance``, an AABB tree; ``O((n_A + n_B)
log n)``). The quadrature is exact for a surface against itself (every
vertex lies on it) and converges as both meshes refine.
"""

import igl
import numpy as np

from mcfbench.geometry.metrics import lumped_mass


def _point_distances(P, V, F):
    """``(p,)`` distances of the points ``P`` to the triangles ``F`` of ``V``
    (validated float64 and int64 arrays)."""
    squared = igl.point_mesh_squared_distance(np.ascontiguousarray(P, dtype=float),
                                              np.ascontiguousarray(V, dtype=float),
                                              np.ascontiguousarray(F, dtype=np.int64))[0]
    return np.sqrt(squared)


def mean_surface_distance(vertices_a, faces_a, vertices_b, faces_b):
    """Symmetric area-weighted mean distance ``D(A, B)`` (module docstring).

    Parameters
    ----------
    vertices_a : (n_a, 3) float array
    faces_a : (m_a, 3) int array
        Surface ``A``.
    vertices_b : (n_b, 3) float array
    faces_b : (m_b, 3) int array
        Surface ``B`` (any mesh: the two need not share vertices or faces).

    Returns
    -------
    float
        In the unit of the coordinates; 0 for a surface against itself.

    Raises
    ------
    ValueError
        A mesh of the wrong shape or without a triangle, or two surfaces of
        zero area.
    """
    meshes = ((vertices_a, faces_a), (vertices_b, faces_b))
    masses = [lumped_mass(V, F) for V, F in meshes]          # validates both meshes
    if any(len(F) == 0 for _, F in meshes):
        raise ValueError("a surface has no triangle: no distance to it")
    total = float(masses[0].sum() + masses[1].sum())
    if not total > 0.0:
        raise ValueError("both surfaces have zero area: no mean distance")
    (VA, FA), (VB, FB) = meshes
    return float(masses[0] @ _point_distances(VA, VB, FB)
                 + masses[1] @ _point_distances(VB, VA, FA)) / total
