"""Initial surfaces: every mesh of the experiments and of the benchmark problems.

Every generator returns ``(vertices, faces)``: a ``(n, 3)`` float64 array and
an ``(m, 3)`` int64 array of triangles, consistently oriented, with normals
pointing outwards (away from the enclosed volume of a closed surface, away
from the axis of a cylinder, away from the centre of a hemisphere, ``+z`` for
a flat patch). Generators are deterministic; the random ones take a ``seed``.
:data:`SURFACES` maps a name to its generator and :func:`make_surface` calls
it with keyword arguments, so problems and the command line refer to a
surface by name.

Counts at the default parameters (``n_F`` vertices, ``n_T`` triangles):

======================== ====== ====== ========= ======================================
name                     n_F    n_T    boundary  what
======================== ====== ====== ========= ======================================
``sphere``               642    1280   none      icosphere level 3 (Table 3.1)
``bumpy_sphere``         642    1280   none      Gaussian bumps (Fig. 3.2)
``random_bumpy_sphere``  162    320    none      random smooth bumps (unit tests)
``cymling``              642    1280   none      flat scalloped lens (Figs. 3.3, 3.4)
``perturbed_sphere``     642    1280   none      icosphere, vertices moved on the sphere
``remeshed_sphere``      642    1280   none      hull of random points on the sphere
``anisotropic_sphere``   450    896    none      UV sphere, 8 x 64, thin triangles
``cylinder``             216    384    2 loops   24 x 8, alternating (catenoid problem)
``hemisphere``           331    600    1 loop    10 rings (Fig. 3.8)
``flat_patch``           376    687    1 loop    jittered Delaunay unit disk, z = 0
``flat_lattice``         42     60     1 loop    6 x 5 unit squares, z = 0 (unit tests)
``torus``                256    512    none      R = 2, r = 0.5, 32 x 8 (genus 1)
``dumbbell``             2546   5088   none      two unit spheres, neck 0.25 (level 1)
``blobby``               2646   5288   none      marching cubes of metaballs, 40^3
``implicit_torus``       4476   8952   none      marching cubes of a tilted torus, 48^3
======================== ====== ====== ========= ======================================

Refinement: the icosphere family (``sphere``, ``bumpy_sphere``,
``cymling``, ``perturbed_sphere``) halves ``h`` per ``level``; so do
``anisotropic_sphere``, ``dumbbell`` and ``flat_patch`` (``level``),
``cylinder`` and ``torus`` (double both counts), ``hemisphere`` (double
``rings``), ``remeshed_sphere`` (4x ``n_points``) and the marching-cubes
surfaces (double ``resolution``).
"""

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import ConvexHull, Delaunay, cKDTree

from mcfbench.geometry.metrics import triangle_normals

# ---------------------------------------------------------------- icosphere


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


# ------------------------------------------------------- spheres and variants


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


def _rotation(ax, ay, az):
    """(3, 3) rotation ``R_z(az) R_y(ay) R_x(ax)``."""
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


# eight bump directions: the corners of a cube, turned so that no bump sits
# on an icosahedron vertex and the picture is not mirror-symmetric
_CUBE = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)

BUMP_CENTRES = _CUBE @ _rotation(0.3, 0.5, 0.2).T / np.sqrt(3.0)
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
    F = ConvexHull(V).simplices.astype(np.int64)
    if len(F) != 2 * len(V) - 4:
        raise ValueError("some points are not vertices of their convex hull; try another seed")
    return V, _orient_away_from(V, F, np.zeros(3))


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
    return _revolution(rho, np.cos(theta), counts)


# --------------------------------------------------------- open surfaces


def cylinder(around=24, along=8, radius=1.0, half_height=0.5, diagonals="alternating"):
    """Open cylinder between the circles of ``radius`` at ``z = +-half_height``.

    ``along + 1`` rings of ``around`` vertices,
    ``x = (R cos phi_j, R sin phi_j, z_k)``, ``z_k`` equally spaced from
    ``-h`` to ``h`` (``numpy.linspace``), ``phi_j = 2 pi j / around``; the
    ``around x along`` quads are cut into two triangles by

    * ``"alternating"``: diagonals alternating like a checkerboard (quad
      ``(j, k)`` cut from ``(j, k)`` to ``(j+1, k+1)`` when ``j + k`` is
      even, else from ``(j+1, k)`` to ``(j, k+1)``): vertices of valence 4
      and 8, and, for even ``along``, mirror-symmetric about ``z = 0`` with
      the middle ring on ``z = 0`` (the catenoid problem: 24 x 8, 48 x 16,
      96 x 32, 192 x 64);
    * ``"parallel"``: every quad cut from ``(j, k)`` to ``(j+1, k+1)``;
    * ``"twisted"``: ring ``k`` turned by ``k / 2`` segments,
      ``phi_j = 2 pi (j + k/2) / around``, and every quad cut from
      ``(j+1, k)`` to ``(j, k+1)``: near-isosceles triangles (Figs.
      3.5-3.7 with ``half_height = 0.55``).

    Both boundary circles are Dirichlet boundaries (1.2). Normals point
    away from the axis. The steady state of the flow is the catenoid
    ``r(z) = a cosh(z / a)`` with ``a cosh(h / a) = R``
    (:func:`mcfbench.geometry.metrics.catenoid_parameter`), which exists for ``h / R``
    below about 0.663; ``R = 1, h = 0.5`` gives ``a = 0.848337938094979``.

    Parameters
    ----------
    around : int
        Vertices per ring, ``>= 3``.
    along : int
        Rows of quads between the circles, ``>= 1``.
    radius, half_height : float
    diagonals : {"alternating", "parallel", "twisted"}

    Returns
    -------
    vertices : ((along + 1) * around, 3) float array
        Vertex ``k * around + j`` is ``(j, k)``; ring 0 at ``z = -h``.
    faces : (2 * along * around, 3) int64 array
        The first triangles of all quads, then the second ones.

    Examples
    --------
    >>> V, F = cylinder()
    >>> len(V), len(F), len(V) + len(F)
    (216, 384, 600)
    """
    if around < 3 or along < 1:
        raise ValueError(f"need around >= 3 and along >= 1, got {around}, {along}")
    if diagonals not in _DIAGONALS:
        raise ValueError(f"diagonals must be one of {', '.join(_DIAGONALS)}, got {diagonals!r}")
    k, j = np.meshgrid(np.arange(along + 1), np.arange(around), indexing="ij")
    phi = 2.0 * np.pi * (j + (0.5 * k if diagonals == "twisted" else 0.0)) / around
    z = np.repeat(np.linspace(-half_height, half_height, along + 1), around)
    V = np.column_stack([radius * np.cos(phi).ravel(), radius * np.sin(phi).ravel(), z])
    return V, _quad_grid(around, along + 1, True, False, diagonals)


def hemisphere(rings=10, radius=1.0):
    """Upper hemisphere ``|x| = R``, ``z >= 0``, with the equator as boundary (Fig. 3.8).

    A polar triangulation: the pole and ``rings`` circles of latitude at
    polar angles ``theta_k = (pi/2) k / rings`` with ``6 k`` equally spaced
    vertices each (the hexagonal-disk pattern), consecutive circles
    zipped together by increasing azimuth. The triangles are close to
    equilateral and of nearly equal size ``h ~ (pi / 2) R / rings``
    (doubling ``rings`` halves ``h``: 5, 10, 20, 40); ``n_F = 1 + 3 K (K + 1)``,
    ``n_T = 6 K^2`` for ``K = rings`` (331 + 600 = 931 for 10 rings).
    The equator (ring ``K``, exactly on ``z = 0``) is a Dirichlet boundary
    (1.2); the steady state is the flat disk. Normals point away from the
    centre.

    Parameters
    ----------
    rings : int
        ``>= 1``.
    radius : float

    Returns
    -------
    vertices : (1 + 3 rings (rings + 1), 3) float array
    faces : (6 rings^2, 3) int64 array

    Examples
    --------
    >>> V, F = hemisphere(8)
    >>> len(V), len(F)
    (217, 384)
    """
    if rings < 1:
        raise ValueError(f"need rings >= 1, got {rings}")
    K = int(rings)
    theta = 0.5 * np.pi * np.arange(K + 1) / K
    counts = np.maximum(6 * np.arange(K + 1), 1)
    V, F = _revolution(np.sin(theta), np.cos(theta), counts, radius)
    V[-counts[-1]:, 2] = 0.0  # exactly on the plane z = 0
    return V, F


def flat_patch(level=1, jitter=0.3, seed=0):
    """Unit disk in the plane ``z = 0`` with irregular interior vertices.

    Mesh size ``h = 0.2 / 2**level``. Boundary: ``round(2 pi / h)`` equally
    spaced points on the unit circle. Interior: the points of the
    hexagonal lattice of spacing ``h`` inside the circle of radius
    ``1 - 0.6 h``, each moved by ``jitter * h * sqrt(u)`` in a random
    direction (``u`` uniform; ``numpy.random.default_rng(seed)``). The
    Delaunay triangulation (:class:`scipy.spatial.Delaunay`) of these points
    has irregular valences; since the boundary points are cocircular, every
    triangle has an interior vertex. Normals point to ``+z``. The circle is
    a Dirichlet boundary (1.2); the exact solution of the flow does not
    move (``H = 0``): every vertex should stay on ``z = 0``.

    Parameters
    ----------
    level : int
        ``>= 0`` (1: ``n_F = 376``, ``n_T = 687``).
    jitter : float
        Random displacement in units of ``h``, ``in [0, 0.4]``.
    seed : int

    Returns
    -------
    vertices : (n, 3) float array
        Interior points first, then the boundary circle counter-clockwise.
    faces : (m, 3) int64 array
    """
    if int(level) != level or level < 0:
        raise ValueError(f"level must be a whole number >= 0, got {level!r}")
    if not 0 <= jitter <= 0.4:
        raise ValueError(f"jitter must lie in [0, 0.4], got {jitter!r}")
    h = 0.2 / 2 ** int(level)
    n = int(np.ceil(1.0 / h)) + 1
    i, j = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
    lattice = h * np.column_stack([(i + 0.5 * j).ravel(), (0.5 * np.sqrt(3.0) * j).ravel()])
    inner = lattice[np.hypot(lattice[:, 0], lattice[:, 1]) < 1.0 - 0.6 * h]
    rng = np.random.default_rng(seed)
    angle = 2.0 * np.pi * rng.uniform(size=len(inner))
    step = jitter * h * np.sqrt(rng.uniform(size=len(inner)))
    inner = inner + step[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    phi = 2.0 * np.pi * np.arange(int(round(2.0 * np.pi / h))) / round(2.0 * np.pi / h)
    xy = np.concatenate([inner, np.column_stack([np.cos(phi), np.sin(phi)])])
    F = Delaunay(xy).simplices.astype(np.int64)
    V = np.column_stack([xy, np.zeros(len(xy))])
    return V, _orient_along(V, F, np.array([0.0, 0.0, 1.0]))


def flat_lattice(m=6, k=5):
    """Unit squares ``[0, m] x [0, k]`` at ``z = 0``, each cut by its ``(0,0)-(1,1)`` diagonal.

    Affine functions are exact on it (assembly and geometry tests).

    Parameters
    ----------
    m, k : int
        Squares along ``x`` and ``y``.

    Returns
    -------
    vertices : ((m + 1)(k + 1), 3) float array
        Vertex ``j (m + 1) + i`` is ``(i, j, 0)``.
    faces : (2 m k, 3) int64 array
        Normals ``+z``.
    """
    x, y = np.meshgrid(np.arange(m + 1.0), np.arange(k + 1.0), indexing="xy")
    V = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    return V, _quad_grid(m + 1, k + 1, False, False, "parallel")


# ------------------------------------------------------ closed, not spheres


def torus(R=2.0, r=0.5, n_major=32, n_minor=8):
    """Torus of revolution about the ``z`` axis (genus 1).

    ``x = ((R + r cos v) cos u, (R + r cos v) sin u, r sin v)`` at
    ``u_i = 2 pi i / n_major``, ``v_j = 2 pi j / n_minor``; the quads are cut
    by alternating diagonals (as :func:`cylinder`). ``n_major / n_minor = R / r``
    gives square quads at the outer equator. The tube pinches under the flow.

    Parameters
    ----------
    R, r : float
        Major and minor radius, ``R > r > 0``.
    n_major, n_minor : int
        Vertices around the axis and around the tube, ``>= 3``.

    Returns
    -------
    vertices : (n_major n_minor, 3) float array
        Vertex ``j n_major + i`` is ``(u_i, v_j)``.
    faces : (2 n_major n_minor, 3) int64 array
        Normals ``(cos v cos u, cos v sin u, sin v)``, outwards.
    """
    if not R > r > 0:
        raise ValueError(f"need R > r > 0, got R = {R!r}, r = {r!r}")
    if n_major < 3 or n_minor < 3:
        raise ValueError(f"need n_major, n_minor >= 3, got {n_major}, {n_minor}")
    v, u = np.meshgrid(2 * np.pi * np.arange(n_minor) / n_minor,
                       2 * np.pi * np.arange(n_major) / n_major, indexing="ij")
    w = R + r * np.cos(v)
    V = np.column_stack([(w * np.cos(u)).ravel(), (w * np.sin(u)).ravel(), (r * np.sin(v)).ravel()])
    return V, _quad_grid(n_major, n_minor, True, True, "alternating")


def dumbbell_profile(z, centre=1.2, neck=0.25, blend=0.05):
    """Squared radius ``r(z)^2`` of the dumbbell: two unit spheres and a neck, smoothly joined.

    ``r^2 = k log(exp(p_+ / k) + exp(p_- / k) + exp(q / k))`` (the
    log-sum-exp smooth maximum, ``k = blend``) of the spheres
    ``p_+- = 1 - (z -+ c)^2`` and the neck ``q = n^2 (1 - (z / c)^8)``. It is analytic, even in ``z``, equals
    the unit spheres up to ``k e^{-(p - q)/k}`` away from the junctions and
    ``n^2`` (to ``1e-5``) at ``z = 0``, and has simple zeros (the poles)
    at ``z = +-(c + 1)`` to rounding.

    Parameters
    ----------
    z : array_like
    centre, neck, blend : float

    Returns
    -------
    ndarray
        ``r(z)^2``, negative beyond the poles.
    """
    z = np.asarray(z, dtype=float)
    terms = np.stack([1.0 - (z - centre) ** 2, 1.0 - (z + centre) ** 2,
                      neck**2 * (1.0 - (z / centre) ** 8)])
    return blend * np.logaddexp.reduce(terms / blend, axis=0)


def dumbbell(level=1):
    """Dumbbell: two unit spheres centred at ``z = +-1.2`` joined by a neck of radius 0.25.

    The surface of revolution ``r(z) = sqrt(`` :func:`dumbbell_profile` ``(z))``
    (its default parameters): two unit spheres and, between them, a
    cylindrical neck of radius 0.25 and length about 0.46 blended in
    smoothly. The neck (``H = 4``) is too long for a catenoid to span it
    (half-length / radius ~ 0.93 > 0.663): it pinches under the flow long
    before the bulbs (``H = 2``) vanish, the standard pinch-off test. (With
    Dziuk's cotangent scheme, level 1, ``tau = 2.5e-4``: neck radius 0.21
    at ``t = 0.025``, 0.13 at 0.075, pinched at ``t ~ 0.096`` while the
    bulbs still have radius 0.79.)

    Mesh size ``h = 0.2 / 2**level``: the meridian (poles at ``z = +-L``,
    ``L ~ 2.2``) is cut into ``K = round(length / h)`` arcs of equal length
    (arc length of the dense curve ``(r(L cos s), L cos s)``, ``s`` in
    ``[0, pi]``); ring ``k`` of radius ``r_k`` gets ``max(3, round(2 pi r_k / h))``
    equally spaced vertices (about ``6 k`` near the poles) and consecutive
    rings are zipped as in :func:`hemisphere`.

    Parameters
    ----------
    level : int
        ``>= 0`` (0: ``n_F = 638``; 1: ``n_F = 2546``, ``n_T = 5088``; 2: 10110).

    Returns
    -------
    vertices : (n, 3) float array
        Top pole, the rings from top to bottom, bottom pole.
    faces : (2 n - 4, 3) int64 array
    """
    if int(level) != level or level < 0:
        raise ValueError(f"level must be a whole number >= 0, got {level!r}")
    h = 0.2 / 2 ** int(level)
    from scipy.optimize import brentq

    L = brentq(dumbbell_profile, 1.5, 4.0, xtol=1e-15)  # the top pole, 2.2 to rounding
    s = np.linspace(0.0, np.pi, 20001)
    z = L * np.cos(s)
    rho = np.sqrt(np.maximum(dumbbell_profile(z), 0.0))
    arc = np.r_[0.0, np.cumsum(np.hypot(np.diff(rho), np.diff(z)))]
    K = max(2, int(round(arc[-1] / h)))
    s_k = np.interp(arc[-1] * np.arange(K + 1) / K, arc, s)
    z_k = L * np.cos(s_k)
    rho_k = np.sqrt(np.maximum(dumbbell_profile(z_k), 0.0))
    rho_k[[0, -1]] = 0.0
    counts = np.maximum(3, np.rint(2.0 * np.pi * rho_k / h)).astype(np.int64)
    counts[[0, -1]] = 1
    return _revolution(rho_k, z_k, counts)


# ------------------------------------------- marching cubes of implicit surfaces


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
    V, F = _clean(V.astype(np.float64) + lower, F.astype(np.int64), weld * d)
    _check_closed_manifold(V, F)
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


_TORUS_TILT = _rotation(0.4, 0.25, 0.1)


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


# ---------------------------------------------------------------- registry

SURFACES = {
    "sphere": sphere,
    "bumpy_sphere": bumpy_sphere,
    "random_bumpy_sphere": random_bumpy_sphere,
    "cymling": cymling,
    "perturbed_sphere": perturbed_sphere,
    "remeshed_sphere": remeshed_sphere,
    "anisotropic_sphere": anisotropic_sphere,
    "cylinder": cylinder,
    "hemisphere": hemisphere,
    "flat_patch": flat_patch,
    "flat_lattice": flat_lattice,
    "torus": torus,
    "dumbbell": dumbbell,
    "blobby": blobby,
    "implicit_torus": implicit_torus,
}
"""Name -> generator of the initial surfaces; ``SURFACES[name](**params)``."""


def make_surface(name, **params):
    """``SURFACES[name](**params)``, with a helpful error for unknown names.

    Examples
    --------
    >>> V, F = make_surface("torus", n_major=16, n_minor=4)
    >>> V.shape, F.shape
    ((64, 3), (128, 3))
    """
    try:
        generator = SURFACES[name]
    except KeyError:
        raise ValueError(f"unknown surface {name!r}; choose one of {', '.join(SURFACES)}") from None
    return generator(**params)


# ----------------------------------------------------------------- helpers

_DIAGONALS = ("alternating", "parallel", "twisted")


def _quad_grid(n_u, n_v, wrap_u, wrap_v, diagonals):
    """Triangles of a grid of quads, counter-clockwise in ``(u, v)``.

    Vertex ``(i, j)`` is ``j n_u + i``; ``wrap_u``/``wrap_v`` join the last
    column/row to the first. Quad ``(i, j)`` has corners ``p = (i, j)``,
    ``q = (i+1, j)``, ``r = (i+1, j+1)``, ``s = (i, j+1)`` and is cut along
    ``p-r`` (``"parallel"``; ``"alternating"`` when ``i + j`` is even) into
    ``(p, q, r), (p, r, s)``, else along ``q-s`` into ``(p, q, s), (q, r, s)``
    (``"twisted"``; ``"alternating"`` when odd). Returns the ``(2 n_quads, 3)``
    int64 array: all first triangles (quads in row-major order), then all
    second ones.
    """
    nu, nv = n_u if wrap_u else n_u - 1, n_v if wrap_v else n_v - 1
    j, i = np.meshgrid(np.arange(nv), np.arange(nu), indexing="ij")
    i, j = i.ravel(), j.ravel()
    i1, j1 = (i + 1) % n_u, (j + 1) % n_v
    p, q, r, s = j * n_u + i, j * n_u + i1, j1 * n_u + i1, j1 * n_u + i
    if diagonals == "parallel":
        along_pr = np.ones(len(p), bool)
    elif diagonals == "twisted":
        along_pr = np.zeros(len(p), bool)
    else:
        along_pr = (i + j) % 2 == 0
    first = np.where(along_pr[:, None], np.column_stack([p, q, r]), np.column_stack([p, q, s]))
    second = np.where(along_pr[:, None], np.column_stack([p, r, s]), np.column_stack([q, r, s]))
    return np.concatenate([first, second]).astype(np.int64)


def _revolution(rho, z, counts, scale=1.0):
    """Surface of revolution about the ``z`` axis through rings of vertices.

    Ring ``k`` (from the top) has ``counts[k]`` vertices
    ``scale * (rho_k cos phi, rho_k sin phi, z_k)``,
    ``phi = 2 pi j / counts[k]``; a ring of one vertex with ``rho_k = 0`` is a
    pole. Consecutive rings are zipped by :func:`_zip_rings`; normals point
    away from the axis when ``z`` decreases along the rings.
    """
    counts = np.asarray(counts, dtype=np.int64)
    start = np.r_[0, np.cumsum(counts)[:-1]]
    ring = np.repeat(np.arange(len(counts)), counts)
    phi = 2.0 * np.pi * (np.arange(counts.sum()) - start[ring]) / counts[ring]
    rho, z = np.asarray(rho, float)[ring], np.asarray(z, float)[ring]
    V = scale * np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])
    F = np.concatenate([_zip_rings(start[k], counts[k], start[k + 1], counts[k + 1])
                        for k in range(len(counts) - 1)])  # one block per pair of rings
    return V, F


def _zip_rings(s_in, m, s_out, M):
    """Triangles between two coaxial rings, swept counter-clockwise.

    The inner ring has ``m`` vertices ``s_in + i`` at azimuths
    ``2 pi i / m``, the outer one ``M`` vertices ``s_out + j`` at
    ``2 pi j / M``. Each triangle advances one ring by one vertex; the
    advances are taken in the order of the azimuth of the vertex they reach
    (ties: inner first), giving ``m + M`` triangles, less the one that
    would repeat a vertex when a ring is a single pole.
    """
    key = np.r_[np.arange(1, m + 1) / m, np.arange(1, M + 1) / M]
    order = np.argsort(key, kind="stable")
    outer = order >= m
    i = np.r_[0, np.cumsum(~outer)][:-1]  # positions before each advance
    j = np.r_[0, np.cumsum(outer)][:-1]
    nxt = np.where(outer, s_out + (j + 1) % M, s_in + (i + 1) % m)
    # (inner, outer, next) is counter-clockwise seen from outside
    tri = np.column_stack([s_in + i % m, s_out + j % M, nxt]).astype(np.int64)
    return tri[(tri[:, 0] != tri[:, 2]) & (tri[:, 1] != tri[:, 2])]


def _orient_away_from(V, F, centre):
    """Reverse the triangles whose normal points towards ``centre``."""
    away = np.einsum("ij,ij->i", triangle_normals(V, F), V[F].mean(axis=1) - centre)
    return np.where((away < 0)[:, None], F[:, ::-1], F)


def _orient_along(V, F, direction):
    """Reverse the triangles whose normal points against ``direction``."""
    return np.where((triangle_normals(V, F) @ direction < 0)[:, None], F[:, ::-1], F)


def _clean(V, F, tol=0.0):
    """Weld vertices closer than ``tol``; drop degenerate, folded and unused elements.

    Each cluster of vertices joined by pairs closer than ``tol`` (and of
    coincident vertices) becomes its first vertex. Triangles repeating a
    vertex or of zero area are dropped, so are all copies of a triangle
    whose vertex set occurs more than once, then unreferenced vertices.
    Vertices and triangles keep their order.
    """
    n = len(V)
    if tol > 0:  # clusters of the graph of pairs closer than tol (coincident ones too)
        pairs = cKDTree(V).query_pairs(tol, output_type="ndarray")
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
        _, cluster = connected_components(graph, directed=False)
    else:  # clusters of coincident vertices
        _, cluster = np.unique(V, axis=0, return_inverse=True)
        cluster = cluster.ravel()
    first = np.full(cluster.max() + 1, n)
    np.minimum.at(first, cluster, np.arange(n))
    size = np.bincount(cluster)
    V = V.copy()
    V[first] = np.column_stack([np.bincount(cluster, weights=V[:, k]) / size for k in range(3)])
    F = first[cluster][F]
    area2 = np.linalg.norm(triangle_normals(V, F), axis=1)
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 2] != F[:, 0]) & (area2 > 0)]
    _, triple, count = np.unique(np.sort(F, axis=1), axis=0,
                                 return_inverse=True, return_counts=True)
    F = F[count[triple.ravel()] == 1]
    used = np.zeros(n, bool)
    used[F.ravel()] = True
    new = np.cumsum(used) - 1
    return V[used], new[F].astype(np.int64)


def _check_closed_manifold(V, F):
    """Raise unless the triangles form a closed, consistently oriented 2-manifold
    (:func:`mcfbench.geometry.mesh.summarize`, which validates first, and no boundary loop)."""
    from mcfbench.geometry.mesh import MeshError, summarize

    try:
        loops = summarize(V, F).boundary_loops
    except MeshError as err:
        raise ValueError(f"marching cubes gave an open or non-manifold mesh: {err}; "
                         "enlarge the box or refine the grid") from None
    if loops:
        raise ValueError(f"marching cubes gave an open or non-manifold mesh: {loops} "
                         "boundary loop(s); enlarge the box or refine the grid")
