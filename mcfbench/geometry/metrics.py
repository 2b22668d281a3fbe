"""Problem metrics and mesh-quality monitors: pure functions of a triangle mesh.

Every function takes ``vertices``, an ``(n, 3)`` float array (one row per
vertex, as the generators of :mod:`mcfbench.geometry.surfaces` return them), and,
where it needs them, ``faces``, an ``(m, 3)`` int array of consistently
oriented triangles; none keeps state. All are vectorized over vertices
and triangles.

Exact answers of the problems (``NOTES.md``, "Exact and reference answers
beyond the sphere"):

* sphere of radius ``R``: ``r(t) = sqrt(R^2 - 4t)``
  (:func:`mcfbench.geometry.exact.sphere_radius`);
* cylinder between the circles of radius ``R`` at ``z = +-h``: the
  catenoid ``r(z) = a cosh(z/a)``, ``a cosh(h/a) = R``
  (:func:`catenoid_parameter`, :func:`catenoid_profile_error`);
* hemisphere with its equator fixed, flat disk: the disk ``z = 0``
  (:func:`max_height`, :func:`l2_height`).

Problem metrics: :func:`catenoid_profile_error`, :func:`max_height`,
:func:`l2_height`, :func:`volume`, :func:`area`. Mesh quality:
:func:`min_angle`, :func:`max_aspect_ratio`, :func:`area_ratio`,
:func:`flipped_triangles`, all four in :func:`quality`. Steady state:
:func:`max_speed`.
"""

import numpy as np

# ------------------------------------------------------------ measures


def triangle_areas(vertices, faces):
    """Area of every triangle, ``|(b - a) x (c - a)| / 2``.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (m,) float array
    """
    return 0.5 * np.linalg.norm(triangle_normals(*_mesh(vertices, faces)), axis=1)


def area(vertices, faces):
    """Surface area, the sum of the triangle areas.

    Examples
    --------
    >>> V = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    >>> area(V, [[0, 1, 2]])
    0.5
    """
    return float(triangle_areas(vertices, faces).sum())


def volume(vertices, faces):
    """Signed enclosed volume ``(1/6) sum_t a_t . (b_t x c_t)`` (divergence theorem).

    Positive for a closed surface whose normals point outwards; for an open
    surface it is the signed volume of the cone from the origin over it.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
        Triangles ``(a, b, c)``.

    Returns
    -------
    float
    """
    V, F = _mesh(vertices, faces)
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    return float(np.einsum("ij,ij->", a, np.cross(b, c)) / 6.0)


def lumped_mass(vertices, faces):
    """Barycentric (lumped) vertex areas: a third of the area of each triangle at the vertex.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (n,) float array
        Sums to :func:`area`.
    """
    V, F = _mesh(vertices, faces)
    third = triangle_areas(V, F) / 3.0
    return np.bincount(F.ravel(), weights=np.repeat(third, 3), minlength=len(V))


def mean_edge_length(vertices, faces):
    """Mean length of the edges, each undirected edge counted once.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    float
    """
    V, F = _mesh(vertices, faces)
    # each edge once as the key min * n + max, its ends (key // n, key % n): the
    # rows of np.unique(..., axis=0) in the same order, 6x faster (10 000 vertices:
    # 9 ms against 55 ms, once per run for h)
    n, a, b = len(V), F.ravel(), F[:, [1, 2, 0]].ravel()
    key = np.unique(np.minimum(a, b).astype(np.int64) * n + np.maximum(a, b))
    return float(np.linalg.norm(V[key % n] - V[key // n], axis=1).mean())


# ----------------------------------------------------- problem metrics


def max_height(vertices):
    """``max_i |z_i|``: distance of the vertices from the plane ``z = 0`` (0 for the flat disk).

    Parameters
    ----------
    vertices : (n, 3) float array

    Returns
    -------
    float
    """
    V = _vertices(vertices)
    return float(np.abs(V[:, 2]).max())


def l2_height(vertices, faces):
    """``sqrt(sum_i m_i z_i^2)``, the lumped L2 norm of the height ``z`` (0 for the flat disk).

    ``m_i`` are the barycentric vertex areas (:func:`lumped_mass`).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    float
    """
    V, F = _mesh(vertices, faces)
    return float(np.sqrt(np.dot(lumped_mass(V, F), V[:, 2] ** 2)))


def catenoid_parameter(radius=1.0, half_height=0.5):
    """Neck radius ``a`` of the stable catenoid spanning the circles of ``radius`` at ``z = +-h``.

    Solves ``a cosh(h / a) = R`` on the branch of the larger root (the
    stable catenoid, the steady state of the flow from the cylinder;
    ``NOTES.md``, "Exact solutions for tests").

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
    >>> round(catenoid_parameter(1.0, 0.5), 15)
    0.848337938094979
    """
    R, h = float(radius), float(half_height)
    # a cosh(h/a) is smallest where tanh(h/a) = a/h
    from scipy.optimize import brentq  # on first use: importing it takes 0.3 s

    a_min = brentq(lambda a: np.tanh(h / a) - a / h, 1e-6 * h, h)
    if a_min * np.cosh(h / a_min) > R:
        raise ValueError(f"no catenoid spans circles of radius {R} at z = +-{h} "
                         f"(h/R = {h / R:.4f} exceeds about 0.6627)")
    return brentq(lambda a: a * np.cosh(h / a) - R, a_min, R,
                  xtol=1e-15, rtol=4 * np.finfo(float).eps)


def catenoid_profile_error(vertices, a, fixed_mask=None, neck_band=None):
    """Distance of a surface about the ``z`` axis from the catenoid ``r = a cosh(z/a)``.

    With ``rho_i = sqrt(x_i^2 + y_i^2)`` over the free vertices (not in
    ``fixed_mask``):

    ``max_radial_error``
        ``max_i |rho_i - a cosh(z_i/a)| / (a cosh(z_i/a))``, the largest
        relative radial error.
    ``neck_radius``
        The mean of ``rho_i / cosh(z_i/a)`` over the neck ring: the free
        vertices whose ``|z_i|`` is within ``neck_band`` of the smallest
        ``|z|`` (for :func:`mcfbench.geometry.shapes.cylinder` with even ``along``
        the middle ring, on ``z = 0``, where this is the mean radius).
        Dividing by ``cosh(z_i/a)`` makes each term exactly ``a`` on the
        catenoid, so a ring slightly off ``z = 0`` still measures the neck.
    ``neck_error``
        ``(neck_radius - a) / a``, signed: negative for a neck thinner than
        the catenoid's.

    Parameters
    ----------
    vertices : (n, 3) float array
        The catenoid's axis is the ``z`` axis, its neck at ``z = 0``.
    a : float
        Catenoid parameter (:func:`catenoid_parameter`), ``> 0``.
    fixed_mask : (n,) bool array or int array of indices, optional
        Vertices to leave out (the boundary circles, exact by construction).
    neck_band : float, optional
        Width of the neck ring in ``z``; default ``1e-3 a``.

    Returns
    -------
    dict
        ``neck_radius``, ``neck_error``, ``max_radial_error`` (floats).
    """
    V = _vertices(vertices)
    if not a > 0:
        raise ValueError(f"the catenoid parameter a must be positive, got {a!r}")
    free = np.ones(len(V), bool)
    if fixed_mask is not None:
        free[np.asarray(fixed_mask)] = False
    if not free.any():
        raise ValueError("every vertex is fixed: nothing to compare with the catenoid")
    rho, z = np.hypot(V[free, 0], V[free, 1]), V[free, 2]
    scale = np.cosh(z / a)
    radial = np.abs(rho - a * scale) / (a * scale)
    band = 1e-3 * a if neck_band is None else float(neck_band)
    ring = np.abs(z) <= np.abs(z).min() + band
    neck = float(np.mean(rho[ring] / scale[ring]))
    return {"neck_radius": neck, "neck_error": (neck - a) / a,
            "max_radial_error": float(radial.max())}


# -------------------------------------------------------- mesh quality


def triangle_angles(vertices, faces):
    """Interior angles in degrees; column ``k`` at corner ``faces[:, k]``.

    ``atan2(|u x v|, u . v)`` of the two edge vectors leaving the corner
    (accurate for angles near 0 and 180 degrees).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (m, 3) float array
        Each row sums to 180.
    """
    V, F = _mesh(vertices, faces)
    u = V[F[:, [1, 2, 0]]] - V[F]
    v = V[F[:, [2, 0, 1]]] - V[F]
    return np.degrees(np.arctan2(np.linalg.norm(np.cross(u, v), axis=2),
                                 np.einsum("ijk,ijk->ij", u, v)))


def min_angle(vertices, faces):
    """Smallest interior angle of the mesh, in degrees (60 for equilateral triangles).

    The smallest angle of a triangle is the one opposite its shortest side:
    one ``atan2(|u x v|, u . v)`` per triangle (:func:`quality`).
    """
    return quality(vertices, faces)["min_angle"]


def aspect_ratios(vertices, faces):
    """Aspect ratio ``R / (2 r)`` of every triangle: circumradius over twice the inradius.

    With side lengths ``a, b, c``, semi-perimeter ``s`` and area ``A``:
    ``R = abc / (4A)``, ``r = A / s``, so ``R / (2r) = abc s / (8 A^2)``
    (``A`` from the cross product). It is 1 for an equilateral triangle
    (the minimum), ``(1 + sqrt 2) / 2 = 1.2071`` for a right isosceles
    one, and ``inf`` for a degenerate one.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (m,) float array
    """
    V, F = _mesh(vertices, faces)
    sides = np.linalg.norm(V[F[:, [1, 2, 0]]] - V[F], axis=2)
    A = triangle_areas(V, F)
    with np.errstate(divide="ignore"):
        return sides.prod(axis=1) * (0.5 * sides.sum(axis=1)) / (8.0 * A**2)


def max_aspect_ratio(vertices, faces):
    """Largest :func:`aspect_ratios` of the mesh (1 when all triangles are equilateral)."""
    return quality(vertices, faces)["max_aspect_ratio"]


def area_ratio(vertices, faces):
    """Largest triangle area over the smallest (``inf`` if a triangle has zero area)."""
    return quality(vertices, faces)["area_ratio"]


def edge_neighbours(faces):
    """Pairs ``(t1, t2)`` of triangles sharing an edge.

    Parameters
    ----------
    faces : (m, 3) int array

    Returns
    -------
    t1, t2 : (k,) int arrays
    """
    F = np.asarray(faces)
    n = int(F.max()) + 1
    src, dst = F.ravel(), F[:, [1, 2, 0]].ravel()
    key = np.minimum(src, dst) * n + np.maximum(src, dst)
    order = np.argsort(key, kind="stable")
    tri = order // 3  # triangle of each sorted half-edge
    shared = key[order][1:] == key[order][:-1]
    return tri[:-1][shared], tri[1:][shared]


def flipped_triangles(vertices, faces, reference_normals=None, neighbours=None):
    """Number of triangles folded over.

    Without ``reference_normals``, triangle ``t`` counts when its normal
    ``n_t = (b - a) x (c - a)`` points against the sum of the normals of
    its edge-neighbours (the triangles sharing an edge with it), i.e.
    against their area-weighted mean normal: ``n_t . sum_s n_s < 0``. A
    single folded triangle in a smooth region counts once (its neighbours
    still agree with theirs). With ``reference_normals`` (e.g. the normals
    of the initial mesh) it counts when ``n_t . reference_t < 0``.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
        Consistently oriented.
    reference_normals : (m, 3) float array, optional
    neighbours : (t1, t2), optional
        :func:`edge_neighbours` of ``faces``, when already known.

    Returns
    -------
    int
    """
    V, F = _mesh(vertices, faces)
    N = triangle_normals(V, F)
    if reference_normals is None:
        reference = _neighbour_normals(N, F, neighbours)
    else:
        reference = np.asarray(reference_normals, dtype=float)
        if reference.shape != N.shape:
            raise ValueError(f"reference_normals must have shape {N.shape} (one per "
                             f"triangle), got {reference.shape}")
    return int((np.einsum("ij,ij->i", N, reference) < 0).sum())


def neighbour_cosines(vertices, faces, neighbours=None):
    """(m,) cosine of the angle between each triangle's normal and the sum of the
    normals of its edge-neighbours (their area-weighted mean normal).

    Negative for a triangle folded over its neighbours (the test of
    :func:`flipped_triangles`); NaN for a degenerate triangle or neighbours whose
    normals cancel.

    Examples
    --------
    >>> V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]])
    >>> neighbour_cosines(V, [[0, 1, 2], [1, 3, 2]]).tolist()
    [1.0, 1.0]
    >>> neighbour_cosines(V, [[0, 1, 2], [1, 2, 3]]).tolist()
    [-1.0, -1.0]
    """
    V, F = _mesh(vertices, faces)
    N = triangle_normals(V, F)
    R = _neighbour_normals(N, F, neighbours)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.einsum("ij,ij->i", N, R) / (np.linalg.norm(N, axis=1)
                                              * np.linalg.norm(R, axis=1))


def _neighbour_normals(N, F, neighbours):
    """(m, 3) sum of the normals ``N`` of each triangle's edge-neighbours."""
    t1, t2 = edge_neighbours(F) if neighbours is None else neighbours
    return np.column_stack([
        np.bincount(t1, N[t2, c], minlength=len(F)) + np.bincount(t2, N[t1, c],
                                                                 minlength=len(F))
        for c in range(3)])


def quality(vertices, faces, neighbours=None):
    """The mesh-quality monitors of one state.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    neighbours : (t1, t2), optional
        :func:`edge_neighbours` of ``faces`` (a monitor of many states
        computes them once).

    Returns
    -------
    dict
        ``min_angle`` (degrees), ``max_aspect_ratio``, ``area_ratio``,
        ``flipped_triangles``: :func:`min_angle`, :func:`max_aspect_ratio`,
        :func:`area_ratio`, :func:`flipped_triangles`.
    """
    V, F = _mesh(vertices, faces)
    if len(F) == 0:
        raise ValueError("a mesh without triangles has no quality")
    t1, t2 = edge_neighbours(F) if neighbours is None else neighbours
    t1, t2 = np.asarray(t1, dtype=np.int64), np.asarray(t2, dtype=np.int64)
    if t1.shape != t2.shape or t1.ndim != 1 or (t1.size > 0 and (
            min(t1.min(), t2.min()) < 0 or max(t1.max(), t2.max()) >= len(F))):
        raise ValueError(f"neighbours must be two equally long arrays of triangle indices "
                         f"in [0, {len(F)})")
    # one compiled pass over the triangles and one over the neighbour pairs (checked
    # against plain numpy evaluations of the same formulas in tests/mcfbench/geometry/test_metrics.py);
    # the arctan2 of the smallest angles is numpy's
    work = np.empty((4, len(F), 3))
    from mcfbench.geometry.kernels import count_folds, quality_pass  # numba on first use

    aspect, a_min, a_max = quality_pass(V, F.astype(np.int64, copy=False), work)
    flipped = count_folds(work[1], t1, t2, np.zeros(len(F), np.uint8), work[2], work[3])
    angle = np.arctan2(work[0, :, 0], work[0, :, 1]).min()
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = float(np.float64(a_max) / np.float64(a_min))
    return {"min_angle": float(np.degrees(angle)), "max_aspect_ratio": float(aspect),
            "area_ratio": ratio, "flipped_triangles": int(flipped)}


# -------------------------------------------------------- steady state


def max_speed(previous, vertices, tau):
    """Largest vertex speed ``max_i |x_i - x_i^prev| / tau`` between two states.

    Parameters
    ----------
    previous, vertices : (n, 3) float arrays
        Two states of the same mesh, ``tau`` apart.
    tau : float
        ``> 0``.

    Returns
    -------
    float
        ``sqrt(max_i |x_i - x_i^prev|^2) / tau``: the largest step, bitwise as
        ``numpy.linalg.norm`` gives it (``sqrt`` is monotone), in one compiled pass
        (:func:`mcfbench.geometry.kernels.largest_step`; the steady state's test
        asks every step of a run, :class:`mcfbench.running.monitors.Steady`, where
        numpy's five passes and temporaries took 15-30 us a step at 3 000 vertices).
    """
    from mcfbench.geometry.kernels import largest_step  # numba on first use

    P, V = _vertices(previous), _vertices(vertices)
    if P.shape != V.shape:
        raise ValueError(f"the two states must have the same shape, got {P.shape} and {V.shape}")
    if not tau > 0:
        raise ValueError(f"tau must be positive, got {tau!r}")
    # Fortran order: the (n, 3) views of the schemes' (3, n) states as they are, one
    # compiled version for every caller
    return float(np.sqrt(largest_step(np.asfortranarray(P), np.asfortranarray(V))) / tau)


# ------------------------------------------------------------- helpers


def _vertices(vertices):
    V = np.asarray(vertices, dtype=float)
    if V.ndim != 2 or V.shape[1] != 3 or len(V) == 0:
        raise ValueError(f"vertices must have shape (n, 3) with n >= 1, got {V.shape}")
    return V


def _mesh(vertices, faces):
    V = _vertices(vertices)
    F = np.asarray(faces)
    if F.ndim != 2 or F.shape[1] != 3 or not np.issubdtype(F.dtype, np.integer):
        raise ValueError(f"faces must be an (m, 3) integer array, got shape {F.shape}, "
                         f"dtype {F.dtype}")
    if F.size and (F.min() < 0 or F.max() >= len(V)):
        raise ValueError(f"face indices must lie in [0, {len(V)}), got [{F.min()}, {F.max()}]")
    return V, F


def triangle_normals(V, F):
    """(m, 3) normals ``(b - a) x (c - a)`` of the triangles ``(a, b, c)`` (length
    twice the area; no validation of the arrays)."""
    return np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])


def covolume_ratio(covolumes, faces):
    """The largest ratio of the covolumes of two vertices joined by an edge.

    The covolume of a vertex is its finite volume (the paper, Section 2.1:
    bounded by the barycentres of its triangles and the midpoints of its
    edges; DDFV: ``chi(V_i^F)``, Section 2.2.4); a scheme's own are its
    quadrature weights (``flow.l2_weights``: the lumped mass of a vertex
    scheme, ``chi / 2`` of DDFV). The ratio is 1 on a mesh of equal
    covolumes and grows where the mesh is graded or degenerates: the local
    quasi-uniformity of the finite volumes, which a tangential motion keeps
    or loses.

    Parameters
    ----------
    covolumes : (n,) float array
        One per vertex of ``faces`` (any common positive factor).
    faces : (m, 3) int array

    Returns
    -------
    float
        ``max over edges (i, j) of max(c_i / c_j, c_j / c_i)``; ``inf`` when
        a covolume is not positive (a collapsed or folded cell), NaN when one
        is not finite.

    Examples
    --------
    >>> import numpy as np
    >>> covolume_ratio(np.array([1.0, 2.0, 4.0, 1.0]), np.array([[0, 1, 2], [0, 2, 3]]))
    4.0
    """
    c = np.asarray(covolumes, dtype=float)
    F = np.asarray(faces)
    if c.ndim != 1 or F.ndim != 2 or F.shape[1] != 3 or F.size == 0 or F.max() >= len(c):
        raise ValueError(f"covolumes must be one per vertex of the faces: got {c.shape} "
                         f"covolumes for faces of shape {F.shape}")
    if not np.isfinite(c).all():
        return float("nan")
    if not (c > 0).all():
        return float("inf")
    a, b = c[F], c[F[:, [1, 2, 0]]]
    return float(np.maximum(a / b, b / a).max())


def final_state_distance(frames, reference, weights):
    """How far the last state of ``frames`` is from the last state of ``reference`` (two
    runs of one scheme on one mesh; :mod:`mcfbench.storage.frames`' layout, ``faces``
    included): ``(error, volume_error)``.

    ``error`` is ``sqrt(sum_i w_i |X_i - X_i^ref|^2)`` over every point of the state
    (DDFV: F- then T-vertices), ``w`` (n_points,) the scheme's quadrature weights of
    the reference (``flow.l2_weights``); ``volume_error`` is ``|vol(X) - vol(X^ref)|``
    of the mesh (:func:`volume`), blind to tangential motion; in this module (not
    :mod:`mcfbench.geometry.frame_fields`, which reads DDFV's geometry) because the
    harness's time study calls it: a DDFV module in every run's code identity otherwise.
    """
    def last(arrays):
        vertices, extra = arrays.get("vertices"), arrays.get("extra_points")
        X = vertices[-1] if extra is None else np.concatenate([vertices[-1], extra[-1]])
        return X.T, volume(vertices[-1], arrays["faces"])

    (X, vol), (ref, ref_volume) = last(frames), last(reference)
    return (float(np.sqrt(np.asarray(weights) @ np.sum((X - ref) ** 2, axis=0))),
            abs(vol - ref_volume))
