"""Spheres: the icosphere of Table 3.1 and the sphere-like surfaces of the experiments and
the benchmark problems (bumps, a scalloped lens, perturbed, remeshed and anisotropic
spheres)."""

import numpy as np

from mcfbench.geometry.construction import orient_away_from, revolution, rotation


def icosahedron():
    """The regular icosahedron inscribed in the unit sphere.

    Returns
    -------
    vertices : (12, 3) float array
    faces : (20, 3) int64 array
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
    ], dtype=np.int64)
    return V / np.linalg.norm(V, axis=1, keepdims=True), F


def subdivide(vertices, faces):
    """Split every triangle into four at its edge midpoints (1-to-4).

    The new vertices follow the old ones, one per edge, the edges sorted by
    the key ``min(i, j) * n + max(i, j)`` of their end points (the order of
    the diamonds of :func:`ddfv.topology.diamond_mesh`, on which the vertex
    order of the Table 3.1 meshes rests).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    vertices : (n + n_edges, 3) float array
    faces : (4 m, 3) int64 array
        Child ``k`` of triangle ``t`` is row ``k m + t``: the corner
        triangles at ``faces[:, 0]``, ``faces[:, 1]``, ``faces[:, 2]``, then
        the middle one.
    """
    faces = np.asarray(faces, dtype=np.int64)
    n = len(vertices)
    src, dst = faces.ravel(), faces[:, [1, 2, 0]].ravel()  # half-edge k of t: row 3 t + k
    keys, edge = np.unique(np.minimum(src, dst) * n + np.maximum(src, dst), return_inverse=True)
    m01, m12, m20 = (n + edge.reshape(-1, 3)).T  # midpoint of each half-edge's edge
    v0, v1, v2 = faces.T
    new_faces = np.concatenate([
        np.column_stack([v0, m01, m20]),
        np.column_stack([v1, m12, m01]),
        np.column_stack([v2, m20, m12]),
        np.column_stack([m01, m12, m20]),
    ])
    midpoints = 0.5 * (vertices[keys // n] + vertices[keys % n])
    return np.concatenate([vertices, midpoints]), new_faces


def icosphere(level, radius=1.0):
    """Sphere mesh of Table 3.1: the icosahedron refined ``level`` times.

    Each refinement splits every triangle into four (:func:`subdivide`) and
    projects the new vertices onto the sphere (Section 3.1). Level 1 has 42
    F- and 80 T-vertices (``n_V = 122``), level 5 has 10242 + 20480.

    Parameters
    ----------
    level : int
        Number of refinements, ``>= 0``.
    radius : float

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
    faces : (20 * 4**level, 3) int64 array

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


def sphere(level=3, radius=1.0):
    """The icosphere of Table 3.1 and Fig. 3.1 (:func:`icosphere`).

    Parameters
    ----------
    level : int
        Refinements of the icosahedron; ``n_V = 30 * 4**level + 2``
        (122, 482, 1922, 7682 for levels 1-4).
    radius : float

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
    faces : (20 * 4**level, 3) int64 array
    """
    return icosphere(level, radius)


# eight bump directions: the corners of a cube, turned so that no bump sits
# on an icosahedron vertex and the picture is not mirror-symmetric
_CUBE = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)


BUMP_CENTRES = _CUBE @ rotation(0.3, 0.5, 0.2).T / np.sqrt(3.0)
"""(8, 3) default bump directions of :func:`bumpy_sphere`."""


def bumpy_sphere(level=3, amplitude=0.25, width=0.2, centres=None):
    """Unit sphere with smooth radial bumps (Fig. 3.2).

    The icosphere of ``level`` is displaced radially,

    ``x = r(d) d,   r(d) = 1 + amplitude * sum_k exp(-|d - c_k|^2 / (2 width^2))``

    with ``d`` the unit direction of a vertex and ``c_k`` the unit bump
    centres (default :data:`BUMP_CENTRES`: the eight corners of a cube,
    rotated). The bumps are Gaussian caps of angular radius about
    ``width`` (two to three edges of the level-3 mesh); at the defaults
    (``amplitude = 0.25``, ``width = 0.2``) they stand 0.25 above the
    sphere, and under the flow with ``tau = 0.0025`` they are half gone at
    ``n = 12`` and almost gone at ``n = 32`` (``t = 0.08``), as in the
    paper's Fig. 3.2.

    Parameters
    ----------
    level : int
        Icosphere level; 3 gives ``n_F = 642``, ``n_T = 1280``, ``n_V = 1922``.
    amplitude : float
        Height of a bump, relative to the unit radius. ``> -1``.
    width : float
        Gaussian width (in units of the chord ``|d - c_k|``). ``> 0``.
    centres : (k, 3) float array, optional
        Bump directions (normalised here).

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
    faces : (20 * 4**level, 3) int64 array

    Examples
    --------
    >>> V, F = bumpy_sphere()
    >>> len(V) + len(F)
    1922
    """
    if not width > 0:
        raise ValueError(f"width must be positive, got {width!r}")
    if not amplitude > -1:
        raise ValueError(f"amplitude must exceed -1 (radius stays positive), got {amplitude!r}")
    d, faces = icosphere(level)
    c = BUMP_CENTRES if centres is None else np.asarray(centres, dtype=float)
    c = c / np.linalg.norm(c, axis=1, keepdims=True)
    dist2 = ((d[:, None, :] - c[None, :, :]) ** 2).sum(axis=2)
    r = 1.0 + amplitude * np.exp(-dist2 / (2.0 * width**2)).sum(axis=1)
    return r[:, None] * d, faces


def random_bumpy_sphere(level=2, amplitude=0.15, seed=0):
    """Icosphere with a smooth, non-symmetric radial bump field (unit tests).

    ``x = r(d) d`` with ``r(d) = 1 + amplitude sin(k_0 . d) cos(k_1 . d + 0.3)``,
    ``d`` the unit direction of an icosphere vertex and ``k_0, k_1`` (and an
    unused ``k_2``) standard normal 3-vectors drawn from
    ``numpy.random.default_rng(seed)``. No symmetry of the sphere survives,
    so operators and flows are tested off their symmetric special cases.

    Parameters
    ----------
    level : int
        Icosphere level (2: ``n_F = 162``, ``n_T = 320``).
    amplitude : float
        ``|amplitude| < 1``.
    seed : int

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
    faces : (20 * 4**level, 3) int64 array
    """
    V, F = icosphere(level)
    rng = np.random.default_rng(seed)
    k = rng.normal(size=(3, 3))
    r = 1.0 + amplitude * np.sin(V @ k[0]) * np.cos(V @ k[1] + 0.3)
    return V * r[:, None], F


def cymling(level=3, flattening=0.4, lobes=9, wave=0.1):
    """Squash-like (pattypan, "cymling") shape: a flat lens with a scalloped rim (Figs. 3.3, 3.4).

    The icosphere of ``level`` with unit directions ``d = (d_x, d_y, d_z)``
    and azimuth ``phi = atan2(d_y, d_x)`` is mapped to

    ``x = rho(phi) d_x,   y = rho(phi) d_y,   z = flattening * d_z,``
    ``rho(phi) = 1 + wave * cos(lobes * phi)``,

    an oblate spheroid of semi-axes ``1`` and ``flattening`` whose rim
    (equator) undulates radially with ``lobes`` scallops. The rim's
    curvature in the meridian plane is ``rho / flattening^2`` (about 6 at
    the defaults) against ``flattening / rho^2`` (~0.4) on the flat top
    and bottom, and the triangles there are squeezed in ``z`` by the
    factor ``flattening``: the region of high initial curvature where the
    diamond cells contract (Fig. 3.4). At the defaults, with
    ``tau = 0.0025``, the first T-vertex leaves its triangle at ``n = 13``,
    just after the last picture of Fig. 3.3 (``n = 12``); flatter shapes
    fail earlier (``flattening = 0.35``: ``n = 9``).

    Parameters
    ----------
    level : int
        Icosphere level; 3 gives ``n_V = 1922``.
    flattening : float
        Half-thickness relative to the radius, in ``(0, 1]``.
    lobes : int
        Number of scallops of the rim.
    wave : float
        Relative amplitude of the scallops, in ``[0, 1)``.

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
    faces : (20 * 4**level, 3) int64 array
    """
    if not 0 < flattening <= 1:
        raise ValueError(f"flattening must lie in (0, 1], got {flattening!r}")
    if not 0 <= wave < 1:
        raise ValueError(f"wave must lie in [0, 1), got {wave!r}")
    d, faces = icosphere(level)
    rho = 1.0 + wave * np.cos(lobes * np.arctan2(d[:, 1], d[:, 0]))
    V = np.column_stack([rho * d[:, 0], rho * d[:, 1], flattening * d[:, 2]])
    return V, faces


def perturbed_sphere(level=3, amplitude=0.25, seed=0):
    """Icosphere whose vertices are moved at random along the unit sphere.

    Every vertex ``d`` of :func:`icosphere` ``(level)`` is moved in a uniformly
    random tangent direction by ``amplitude * h * u``, ``u`` uniform in
    ``[0, 1)`` and ``h`` the mean edge length, then projected back onto the
    sphere: ``x = (d + delta) / |d + delta|``. The surface stays the unit
    sphere (exact solution ``r(t) = sqrt(1 - 4t)``) while the triangles lose
    the icosphere's regularity. ``amplitude`` is capped at 0.3: there, for
    levels 0-5 and 50 seeds each, no triangle folded and the smallest angle
    stayed above 15 degrees (the icosphere's is 54 at level 3).

    Parameters
    ----------
    level : int
        Icosphere level (3: ``n_F = 642``, ``n_T = 1280``).
    amplitude : float
        Largest displacement in units of the mean edge length, ``in [0, 0.3]``.
    seed : int
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
        On the unit sphere (``|x| = 1`` to rounding).
    faces : (20 * 4**level, 3) int64 array
    """
    if not 0 <= amplitude <= 0.3:
        raise ValueError(f"amplitude must lie in [0, 0.3] (no folded triangle), got {amplitude!r}")
    d, faces = icosphere(level)
    h = np.linalg.norm(d[faces] - d[faces[:, [1, 2, 0]]], axis=2).mean()
    rng = np.random.default_rng(seed)
    g = rng.normal(size=d.shape)
    tangent = g - np.einsum("ij,ij->i", g, d)[:, None] * d
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    x = d + (amplitude * h * rng.uniform(size=len(d)))[:, None] * tangent
    return x / np.linalg.norm(x, axis=1, keepdims=True), faces


def remeshed_sphere(n_points=642, seed=0):
    """Convex hull of random points on the unit sphere.

    ``n_points`` directions drawn uniformly on the sphere (normalised
    standard normal 3-vectors of ``numpy.random.default_rng(seed)``) are
    triangulated by their convex hull (:class:`scipy.spatial.ConvexHull`,
    Qhull); every point is a hull vertex, so ``n_T = 2 n_F - 4``. The
    triangles are as irregular as the point set: valences and sizes vary
    and slivers occur, but every vertex lies on the unit sphere (exact
    solution ``r(t) = sqrt(1 - 4t)``).

    Parameters
    ----------
    n_points : int
        ``>= 4`` (642: ``n_T = 1280``, as the icosphere of level 3).
    seed : int

    Returns
    -------
    vertices : (n_points, 3) float array
        In the order drawn, ``|x| = 1`` to rounding.
    faces : (2 n_points - 4, 3) int64 array
        Each hull facet turned so that its normal points away from the origin.
    """
    if n_points < 4:
        raise ValueError(f"need n_points >= 4, got {n_points}")
    rng = np.random.default_rng(seed)
    V = rng.normal(size=(int(n_points), 3))
    V /= np.linalg.norm(V, axis=1, keepdims=True)
    from scipy.spatial import ConvexHull  # on first use: scipy.spatial takes 0.1-0.4 s

    F = ConvexHull(V).simplices.astype(np.int64)
    if len(F) != 2 * len(V) - 4:
        raise ValueError("some points are not vertices of their convex hull; try another seed")
    return V, orient_away_from(V, F, np.zeros(3))


def anisotropic_sphere(level=1, stretch=4.0):
    """Unit UV sphere with far more longitudes than latitudes: long, thin triangles.

    ``n_lat = 4 * 2**level`` bands of latitude (equal polar-angle steps
    ``pi / n_lat``) and ``n_lon = round(2 stretch n_lat)`` equal longitude
    steps; each quad of the latitude-longitude grid is cut by one diagonal
    and the two poles are single vertices with fans of ``n_lon`` triangles.
    Near the equator a triangle is ``pi / n_lat`` long and
    ``2 pi / n_lon`` wide, the ratio ``stretch``; towards the poles the
    width shrinks with ``sin(theta)`` (the pole fans have angles
    ``2 pi / n_lon`` at the pole). All vertices lie on the unit sphere, so
    the exact solution ``r(t) = sqrt(1 - 4t)`` still holds.

    Parameters
    ----------
    level : int
        ``>= 0``; each level halves both steps.
    stretch : float
        Length-to-width ratio of the equatorial triangles, ``>= 0.5``
        (``1``: about isotropic at the equator).

    Returns
    -------
    vertices : (2 + (n_lat - 1) n_lon, 3) float array
        North pole, the rings from north to south, south pole.
    faces : (2 n_lon (n_lat - 1), 3) int64 array

    Examples
    --------
    >>> V, F = anisotropic_sphere()
    >>> len(V), len(F)
    (450, 896)
    """
    if int(level) != level or level < 0:
        raise ValueError(f"level must be a whole number >= 0, got {level!r}")
    if not stretch >= 0.5:
        raise ValueError(f"stretch must be at least 0.5, got {stretch!r}")
    n_lat = 4 * 2 ** int(level)
    n_lon = int(round(2 * stretch * n_lat))
    theta = np.pi * np.arange(n_lat + 1) / n_lat
    rho = np.sin(theta)
    rho[[0, -1]] = 0.0
    counts = np.full(n_lat + 1, n_lon)
    counts[[0, -1]] = 1
    return revolution(rho, np.cos(theta), counts)
