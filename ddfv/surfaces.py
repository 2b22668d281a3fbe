"""Initial surfaces (Section 3)."""

import numpy as np

from .topology import diamond_mesh


def icosahedron():
    """The regular icosahedron inscribed in the unit sphere.

    Returns
    -------
    vertices : (12, 3) float array
    faces : (20, 3) int array
        Oriented with outward normals.
    """
    g = (1.0 + np.sqrt(5.0)) / 2.0
    V = np.array([
        [-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0],
        [0, -1, g], [0, 1, g], [0, -1, -g], [0, 1, -g],
        [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1],
    ], dtype=float)
    F = np.array([
        [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
        [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
        [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
        [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
    ])
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


def subdivide(vertices, faces):
    """Split every triangle into four at its edge midpoints (1-to-4).

    New vertices follow the old ones, one per edge in the order of
    :func:`ddfv.topology.diamond_mesh`.

    Returns
    -------
    vertices : (n_f + n_e, 3) float array
    faces : (4 n_t, 3) int array
    """
    mesh = diamond_mesh(faces, len(vertices))
    a, b = mesh.diamonds[:, 0], mesh.diamonds[:, 1]
    mid = len(vertices) + mesh.halfedges  # midpoint of each half-edge's edge
    v0, v1, v2 = faces.T
    m01, m12, m20 = mid.T
    new_faces = np.concatenate([
        np.column_stack([v0, m01, m20]),
        np.column_stack([v1, m12, m01]),
        np.column_stack([v2, m20, m12]),
        np.column_stack([m01, m12, m20]),
    ])
    new_vertices = np.concatenate([vertices, 0.5 * (vertices[a] + vertices[b])])
    return new_vertices, new_faces


def icosphere(level, radius=1.0):
    """Sphere mesh of Table 3.1: the icosahedron refined ``level`` times.

    Each refinement splits every triangle into four and projects the new
    vertices onto the sphere (Section 3.1). Level 1 has 42 F- and 80
    T-vertices (n_V = 122), level 5 has 10242 + 20480.

    Parameters
    ----------
    level : int
        Number of refinements, ``>= 0``.
    radius : float

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
    faces : (20 * 4**level, 3) int array

    Examples
    --------
    >>> V, F = icosphere(1)
    >>> V.shape, F.shape
    ((42, 3), (80, 3))
    """
    if int(level) != level or level < 0:
        raise ValueError(f"icosphere level must be a whole number >= 0, got {level!r}")
    V, F = icosahedron()
    for _ in range(int(level)):
        V, F = subdivide(V, F)
        V /= np.linalg.norm(V, axis=1, keepdims=True)
    return radius * V, F
