"""Initial surfaces of the experiments of Section 3 (Figs. 3.1-3.8).

Every generator returns ``(vertices, faces)``: a ``(n, 3)`` float array and
a ``(m, 3)`` int array of triangles, consistently oriented with normals
pointing outwards (away from the enclosed volume of a closed surface, away
from the axis of the cylinder, away from the centre of the hemisphere).
``SHAPES`` maps a name to its generator so the pipeline and the command
line can refer to a surface by name; keyword arguments are the shape's
parameters.

=================  ======  ======  ======  ========================
name               n_F     n_T     n_V     boundary
=================  ======  ======  ======  ========================
``sphere``         642     1280    1922    none (level 3)
``bumpy_sphere``   642     1280    1922    none (level 3)
``cymling``        642     1280    1922    none (level 3)
``cylinder``       216     384     600     two circles
``hemisphere``     331     600     931     the equator (10 rings)
=================  ======  ======  ======  ========================
"""

import numpy as np
from scipy.optimize import brentq

from .surfaces import icosphere


def sphere(level=3, radius=1.0):
    """The icosphere of Table 3.1 and Fig. 3.1 (see :func:`ddfv.icosphere`).

    Parameters
    ----------
    level : int
        Refinements of the icosahedron; ``n_V = 30 * 4**level + 2``
        (122, 482, 1922, 7682 for levels 1-4).
    radius : float

    Returns
    -------
    vertices : (10 * 4**level + 2, 3) float array
    faces : (20 * 4**level, 3) int array
    """
    return icosphere(level, radius)


# eight bump directions: the corners of a cube, turned so that no bump sits
# on an icosahedron vertex and the picture is not mirror-symmetric
_CUBE = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)


def _rotation(ax, ay, az):
    cx, sx, cy, sy, cz, sz = np.cos(ax), np.sin(ax), np.cos(ay), np.sin(ay), np.cos(az), np.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


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
    faces : (20 * 4**level, 3) int array

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
    faces : (20 * 4**level, 3) int array
    """
    if not 0 < flattening <= 1:
        raise ValueError(f"flattening must lie in (0, 1], got {flattening!r}")
    if not 0 <= wave < 1:
        raise ValueError(f"wave must lie in [0, 1), got {wave!r}")
    d, faces = icosphere(level)
    rho = 1.0 + wave * np.cos(lobes * np.arctan2(d[:, 1], d[:, 0]))
    V = np.column_stack([rho * d[:, 0], rho * d[:, 1], flattening * d[:, 2]])
    return V, faces


def cylinder(segments=24, bands=8, radius=1.0, half_height=0.55, twist=True):
    """Open cylinder between the circles of ``radius`` at ``z = +-half_height`` (Figs. 3.5-3.7).

    ``bands + 1`` rings of ``segments`` vertices,
    ``x = (R cos phi_j, R sin phi_j, z_k)``, ``z_k = -h + 2 h k / bands``,
    ``phi_j = 2 pi (j + k/2) / segments`` when ``twist`` (each ring turned by
    half a segment, so every quad splits into two near-isosceles triangles)
    else ``2 pi j / segments``. Both boundary circles are Dirichlet
    boundaries (1.2). Normals point away from the axis.

    The steady state of the flow is the catenoid ``r(z) = a cosh(z / a)``
    with ``a cosh(h / a) = R`` (:func:`catenoid_waist`), which exists for
    ``h / R`` below about 0.663; at the default ``h / R = 0.55`` its waist
    is ``a = 0.805 R``.

    Parameters
    ----------
    segments : int
        Vertices per ring (24: ``n_F = 216``, ``n_T = 384``, ``n_V = 600``
        with 8 bands).
    bands : int
        Rows of quads between the circles.
    radius, half_height : float
    twist : bool

    Returns
    -------
    vertices : ((bands + 1) * segments, 3) float array
    faces : (2 * bands * segments, 3) int array

    Examples
    --------
    >>> V, F = cylinder()
    >>> len(V), len(F), len(V) + len(F)
    (216, 384, 600)
    """
    if segments < 3 or bands < 1:
        raise ValueError(f"need segments >= 3 and bands >= 1, got {segments}, {bands}")
    k, j = np.meshgrid(np.arange(bands + 1), np.arange(segments), indexing="ij")
    phi = 2.0 * np.pi * (j + (0.5 * k if twist else 0.0)) / segments
    z = -half_height + 2.0 * half_height * k / bands
    V = np.column_stack([radius * np.cos(phi).ravel(), radius * np.sin(phi).ravel(), z.ravel()])
    # quad (k, j): corners p = (k, j), q = (k, j+1), r = (k+1, j+1), s = (k+1, j)
    kk, jj = k[:-1].ravel(), j[:-1].ravel()
    p = kk * segments + jj
    q = kk * segments + (jj + 1) % segments
    s = p + segments
    r = q + segments
    # counter-clockwise seen from outside (phi increasing, then z up)
    if twist:  # ring k+1 is turned by +half a segment: split along q-s
        faces = np.concatenate([np.column_stack([p, q, s]), np.column_stack([q, r, s])])
    else:
        faces = np.concatenate([np.column_stack([p, q, r]), np.column_stack([p, r, s])])
    return V, faces


def hemisphere(rings=10, radius=1.0):
    """Upper hemisphere ``|x| = R``, ``z >= 0``, with the equator as boundary (Fig. 3.8).

    A polar triangulation: the pole and ``rings`` circles of latitude at
    polar angles ``theta_k = (pi/2) k / rings`` with ``6 k`` equally spaced
    vertices each (the hexagonal-disk pattern), consecutive circles
    zipped together by increasing azimuth. The triangles are close to
    equilateral and of nearly equal size; ``n_F = 1 + 3 K (K + 1)``,
    ``n_T = 6 K^2`` for ``K = rings`` (331 + 600 = 931 for 10 rings).
    The equator (ring ``K``) is a Dirichlet boundary (1.2); the steady
    state is the flat unit disk. Normals point away from the centre.

    Parameters
    ----------
    rings : int
    radius : float

    Returns
    -------
    vertices : (1 + 3 rings (rings + 1), 3) float array
    faces : (6 rings^2, 3) int array

    Examples
    --------
    >>> V, F = hemisphere(8)
    >>> len(V), len(F)
    (217, 384)
    """
    if rings < 1:
        raise ValueError(f"need rings >= 1, got {rings}")
    K = int(rings)
    counts = 6 * np.arange(K + 1)
    counts[0] = 1
    start = np.r_[0, np.cumsum(counts)[:-1]]
    ring = np.repeat(np.arange(K + 1), counts)
    j = np.arange(counts.sum()) - start[ring]
    theta = 0.5 * np.pi * ring / K
    phi = 2.0 * np.pi * j / counts[ring]
    V = radius * np.column_stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi),
                                  np.cos(theta)])
    V[:, 2] = np.where(ring == K, 0.0, V[:, 2])  # exactly on the plane z = 0
    faces = [np.column_stack([np.zeros(6, int), 1 + np.arange(6), 1 + (np.arange(1, 7) % 6)])]
    for k in range(2, K + 1):
        faces.append(_zip_rings(start[k - 1], counts[k - 1], start[k], counts[k]))
    return V, np.concatenate(faces)


def _zip_rings(s_in, m, s_out, M):
    """Triangles between two coaxial rings, swept counter-clockwise.

    The inner ring has ``m`` vertices ``s_in + i`` at azimuths
    ``2 pi i / m``, the outer one ``M`` vertices ``s_out + j`` at
    ``2 pi j / M``. Each triangle advances one ring by one vertex; the
    advances are taken in the order of the azimuth of the vertex they reach
    (ties: inner first), giving ``m + M`` triangles.
    """
    key = np.r_[np.arange(1, m + 1) / m, np.arange(1, M + 1) / M]
    order = np.argsort(key, kind="stable")
    outer = order >= m
    i = np.r_[0, np.cumsum(~outer)][:-1]  # positions before each advance
    j = np.r_[0, np.cumsum(outer)][:-1]
    nxt = np.where(outer, s_out + (j + 1) % M, s_in + (i + 1) % m)
    # (inner, outer, next) is counter-clockwise seen from outside
    return np.column_stack([s_in + i % m, s_out + j % M, nxt])


def catenoid_waist(radius=1.0, half_height=0.55):
    """Waist ``a`` of the stable catenoid spanning two circles.

    Solves ``a cosh(h / a) = R`` on the branch of the larger root (the
    stable catenoid, the limit of the flow from the cylinder).

    Parameters
    ----------
    radius : float
        ``R``, radius of the circles at ``z = +-h``.
    half_height : float
        ``h``.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        When ``h / R`` exceeds the critical ratio ~0.6627 (no catenoid).

    Examples
    --------
    >>> round(catenoid_waist(1.0, 0.5), 4)
    0.8483
    """
    R, h = float(radius), float(half_height)
    # a cosh(h/a) is smallest where tanh(h/a) = a/h
    a_min = brentq(lambda a: np.tanh(h / a) - a / h, 1e-6 * h, h)
    if a_min * np.cosh(h / a_min) > R:
        raise ValueError(f"no catenoid spans circles of radius {R} at z = +-{h} "
                         f"(h/R = {h / R:.4f} exceeds about 0.6627)")
    return brentq(lambda a: a * np.cosh(h / a) - R, a_min, R)


SHAPES = {
    "sphere": sphere,
    "bumpy_sphere": bumpy_sphere,
    "cymling": cymling,
    "cylinder": cylinder,
    "hemisphere": hemisphere,
}
"""Name -> generator of the initial surfaces; ``SHAPES[name](**params)``."""


def make_shape(name, **params):
    """``SHAPES[name](**params)`` with a helpful error for unknown names."""
    try:
        generator = SHAPES[name]
    except KeyError:
        raise ValueError(f"unknown shape {name!r}; choose one of {', '.join(SHAPES)}") from None
    return generator(**params)
