"""Open and non-spherical surfaces: the cylinder between two circles (catenoid problem),
the hemisphere, flat patches, the torus and the dumbbell."""

import numpy as np

from mcfbench.geometry.construction import (
    DIAGONALS,
    orient_along,
    quad_grid,
    revolution,
)


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
    if diagonals not in DIAGONALS:
        raise ValueError(f"diagonals must be one of {', '.join(DIAGONALS)}, got {diagonals!r}")
    k, j = np.meshgrid(np.arange(along + 1), np.arange(around), indexing="ij")
    phi = 2.0 * np.pi * (j + (0.5 * k if diagonals == "twisted" else 0.0)) / around
    z = np.repeat(np.linspace(-half_height, half_height, along + 1), around)
    V = np.column_stack([radius * np.cos(phi).ravel(), radius * np.sin(phi).ravel(), z])
    return V, quad_grid(around, along + 1, True, False, diagonals)


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
    V, F = revolution(np.sin(theta), np.cos(theta), counts, radius)
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
    from scipy.spatial import Delaunay  # on first use: scipy.spatial takes 0.1-0.4 s

    F = Delaunay(xy).simplices.astype(np.int64)
    V = np.column_stack([xy, np.zeros(len(xy))])
    return V, orient_along(V, F, np.array([0.0, 0.0, 1.0]))


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
    return V, quad_grid(m + 1, k + 1, False, False, "parallel")


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
    return V, quad_grid(n_major, n_minor, True, True, "alternating")


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
    return revolution(rho_k, z_k, counts)
