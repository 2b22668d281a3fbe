"""Geometry of the diamond mesh at one time level, vectorized over diamonds.

Notation of the paper (Sections 2.2.3-2.2.5) per diamond ``(a, b, t1, t2)``:
``u = F_b - F_a``, ``v = T_t2 - T_t1``, ``S = (F_a + F_b + T_t1 + T_t2) / 4``,
``J = |u x v| = 2 chi(V^D)``. On a boundary diamond (``t2 = -1``) the
missing T-vertex is the reflection ``F_a + F_b - T_t1`` (end of Section
2.2.5), so ``S`` is the edge midpoint and the cell is the triangle
``F_a, F_b, T_t1`` (see ``ddfv/README.md``).

The per-step functions (:func:`diamond_geometry`, :func:`covolume_areas`,
:func:`vertex_normals`, :func:`t_barycentric`) are one compiled loop each,
in :mod:`ddfv.kernels` (numba, imported on first use).
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DiamondGeometry:
    """Per-diamond quantities; vectors are stored by components.

    Attributes
    ----------
    u, v : (3, n_d) float arrays, or None
        The diagonals ``F_b - F_a`` and ``T_t2 - T_t1`` (2.3) (None when
        not asked for, :func:`diamond_geometry`).
    e : (3, n_d) float array, or None
        ``(F_a + F_b - T_t1 - T_t2) / 4``: with ``S`` the centre
        ``bar-phi(C)`` (Section 2.2.2), ``F_a - S = e - u/2``,
        ``F_b - S = e + u/2``, ``T_t1 - S = -e - v/2``, ``T_t2 - S = -e + v/2``.
    len_u, len_v : (n_d,) float arrays
        ``|u|`` and ``d^T = |v|`` (2.8).
    J : (n_d,) float array
        ``|u x v| = 2 chi(V^D)`` (2.8).
    uv : (n_d,) float array
        ``u . v``; ``cot omega = uv / J`` (2.8).
    gamma_t : (n_d,) float array
        ``|gamma^T| = |T_t1 - S| + |T_t2 - S|``, the dual curve crossing
        ``u`` (2.5).
    gamma_f : (n_d,) float array
        ``|gamma^F| = |F_a - S| + |F_b - S|``, the dual curve crossing
        ``v`` (2.15).
    quarters : (4, n_d) float array, or None
        Areas of the triangles ``(F_a, T_t1, S)``, ``(F_a, S, T_t2)``,
        ``(F_b, T_t1, S)``, ``(F_b, S, T_t2)`` that cut the diamond at
        ``S`` (Section 2.2.4), see :func:`covolume_areas`; zero on the
        ``T_t2`` side of boundary diamonds.

    Notes
    -----
    The arrays of one geometry are rows of one buffer whose row stride is
    padded (:func:`ddfv.kernels.padded_length`): the (3, n_d) and (4, n_d)
    fields are views with a row stride above ``n_d``, not C-contiguous.
    """

    u: np.ndarray
    v: np.ndarray
    e: np.ndarray
    len_u: np.ndarray
    len_v: np.ndarray
    J: np.ndarray
    uv: np.ndarray
    gamma_t: np.ndarray
    gamma_f: np.ndarray
    quarters: np.ndarray


def diamond_corners(mesh, F, T):
    """The four corners ``F_a, F_b, T_t1, T_t2`` of every diamond.

    Parameters
    ----------
    mesh : DiamondMesh
    F : (n_f, 3) float array
    T : (n_t, 3) float array

    Returns
    -------
    tuple of four (3, n_d) float arrays
        On boundary diamonds ``T_t2`` is the reflection ``F_a + F_b - T_t1``.
    """
    a, b, t1, t2 = mesh.diamonds.T
    Fc, Tc = F.T, T.T
    Fa, Fb = np.take(Fc, a, axis=1), np.take(Fc, b, axis=1)
    T1, T2 = np.take(Tc, t1, axis=1), np.take(Tc, t2, axis=1)
    if mesh.has_boundary:  # t2 = -1 picked the last T-vertex: replace it
        bnd = mesh.boundary
        T2[:, bnd] = Fa[:, bnd] + Fb[:, bnd] - T1[:, bnd]
    return Fa, Fb, T1, T2


DUAL_LENGTHS = ("broken", "chord")


def diamond_geometry(mesh, F, T, dual_length="broken", threads=1, vectors=True,
                     covolumes=None):
    """Geometric factors of all diamonds, see :class:`DiamondGeometry`.

    One pass over the diamonds (:func:`ddfv.kernels.diamond_geometry_kernel`)
    gathers the corners and computes every length and area from the Gram
    matrix of ``u, v, e`` (``|x x y|^2 = |x|^2 |y|^2 - (x.y)^2``):
    with ``S`` the centre, ``|F_a - S|^2 = |u|^2/4 + |e|^2 - u.e`` etc., and
    the quarter ``(F_a, T_t1, S)`` has area
    ``sqrt(|F_a - S|^2 |T_t1 - S|^2 - ((F_a - S).(T_t1 - S))^2) / 2``.

    Parameters
    ----------
    mesh : DiamondMesh
    F : (n_f, 3) float array
    T : (n_t, 3) float array
    dual_length : {"broken", "chord"}
        ``|gamma|`` as the paper's broken line through ``S`` (2.5), or as the
        chord (``|gamma^T| = |v|``, ``|gamma^F| = |u|``).
    threads : int
        Threads of the pass (:func:`kept_factor.threads.threaded`).
    vectors : bool
        Also keep ``u``, ``v``, ``e`` (otherwise None: the scheme needs
        them only for the vertex normals of (3.6)).
    covolumes : (n_f + n_t,) float array, optional
        Filled with the covolume areas in the same pass (as
        :func:`covolume_areas`, bitwise on one thread); ``quarters`` is then
        None.

    Returns
    -------
    DiamondGeometry
    """
    if dual_length not in DUAL_LENGTHS:
        raise ValueError(f"unknown dual_length {dual_length!r}; choose one of "
                         f"{', '.join(DUAL_LENGTHS)}")
    from . import kernels as k
    from kept_factor.threads import for_threads

    F, T = _coordinates(F, mesh.n_f, "F"), _coordinates(T, mesh.n_t, "T")
    diamonds = _diamond_indices(mesh)
    n_d = diamonds.shape[1]
    buf = np.empty((k.GEOMETRY_ROWS, k.padded_length(n_d)))
    broken = dual_length == "broken"
    scatter = covolumes is not None
    if scatter and (covolumes.shape != (mesh.n_unknowns,) or covolumes.dtype != np.float64):
        raise ValueError(f"covolumes must be a ({mesh.n_unknowns},) float64 array")
    chi = covolumes if scatter else np.empty(0)
    for_threads(k.diamond_geometry_kernel, threads)(
        F, T, diamonds, *mesh.diamond_blocks(threads), broken, vectors, scatter,
        chi[:mesh.n_f], chi[mesh.n_f:], buf)
    rows = buf[:, :n_d]
    len_u, len_v = rows[k.ROW_LEN_U], rows[k.ROW_LEN_V]
    u, v, e = ((rows[k.ROW_U:k.ROW_U + 3], rows[k.ROW_V:k.ROW_V + 3],
                rows[k.ROW_E:k.ROW_E + 3]) if vectors else (None, None, None))
    return DiamondGeometry(
        u=u, v=v, e=e, len_u=len_u, len_v=len_v,
        J=rows[k.ROW_J], uv=rows[k.ROW_UV],
        gamma_t=rows[k.ROW_GAMMA_T] if broken else len_v,
        gamma_f=rows[k.ROW_GAMMA_F] if broken else len_u,
        quarters=None if scatter else rows[k.ROW_QUARTERS:k.ROW_QUARTERS + 4])


def covolume_areas(mesh, geom, threads=1):
    """Areas ``chi(V_i^F)`` and ``chi(V_i^T)`` of the covolumes (Section 2.2.4).

    Each diamond is cut by its centre ``S`` into four triangles
    ``(F_a, T_t1, S)``, ``(F_a, S, T_t2)``, ``(F_b, T_t1, S)``,
    ``(F_b, S, T_t2)``; each belongs to one F- and one T-covolume, so both
    families tile the surface once (hence the ``/2`` in (3.2)). A boundary
    diamond contributes only its two triangles on the side of ``T_t1``.

    Parameters
    ----------
    mesh : DiamondMesh
    geom : DiamondGeometry
    threads : int
        Threads of the scatter (:meth:`DiamondMesh.diamond_blocks`).

    Returns
    -------
    chi_f : (n_f,) float array
    chi_t : (n_t,) float array
        Views of one (n_f + n_t,) buffer, F-vertices first.
    """
    from .kernels import covolume_kernel
    from kept_factor.threads import for_threads

    diamonds = _diamond_indices(mesh)
    quarters = _diamond_array(geom.quarters, (4, diamonds.shape[1]), "quarters")
    chi = np.empty(mesh.n_unknowns)
    chi_f, chi_t = chi[:mesh.n_f], chi[mesh.n_f:]
    for_threads(covolume_kernel, threads)(diamonds, quarters, *mesh.diamond_blocks(threads),
                                         chi_f, chi_t)
    return chi_f, chi_t


def vertex_normals(mesh, geom):
    """Unit normals at F- and T-vertices for the elimination (3.6).

    The normal of a diamond cell is ``u x v / J`` (one orientation for all
    diamonds of a consistently oriented mesh); the normal at a vertex is the
    normalised sum of ``u x v = 2 chi(V^D) N^D`` over the diamonds of its
    covolume, i.e. the area-weighted mean of the diamond normals.

    Parameters
    ----------
    mesh : DiamondMesh
    geom : DiamondGeometry

    Returns
    -------
    (3, n_f + n_t) float array
    """
    from .kernels import vertex_normals_kernel

    diamonds = _diamond_indices(mesh)
    shape = (3, diamonds.shape[1])
    N = np.empty((3, mesh.n_unknowns))
    vertex_normals_kernel(diamonds, _diamond_array(geom.u, shape, "u"),
                          _diamond_array(geom.v, shape, "v"), mesh.n_f, N)
    return N


def triangle_areas(F, faces):
    """(n_t,) areas of the triangles of the primal mesh."""
    p0, p1, p2 = np.take(F.T, faces.T, axis=1).swapaxes(0, 1)
    return 0.5 * _norm(_cross(p1 - p0, p2 - p0))


def t_barycentric(F, T, faces, return_min=False, threads=1):
    """Barycentric coordinates of each T-vertex projected into its triangle.

    ``(1/3, 1/3, 1/3)`` at the barycentre; a negative coordinate means the
    projection of ``T_i`` has left the triangle (Section 3.2). The
    coordinates ``(1 - l1 - l2, l1, l2)`` solve the normal equations
    ``G (l1, l2) = (e1.d, e2.d)`` with ``e1 = p1 - p0``, ``e2 = p2 - p0``,
    ``d = T_i - p0`` and ``G`` the Gram matrix of ``e1, e2``
    (:func:`ddfv.kernels.t_barycentric_kernel`).

    Parameters
    ----------
    F : (n_f, 3) float array
    T : (n_t, 3) float array
    faces : (n_t, 3) int array
    return_min : bool
        Also return the smallest coordinate (``out.min()``, computed in the
        same pass).
    threads : int
        Threads of the pass (:func:`kept_factor.threads.threaded`).

    Returns
    -------
    (n_t, 3) float array
        With ``return_min``: ``(coordinates, smallest)``.
    """
    from .kernels import t_barycentric_kernel, unsigned
    from kept_factor.threads import for_threads

    faces = np.asarray(faces)
    if faces.ndim != 2 or faces.shape[1] != 3 or not np.issubdtype(faces.dtype, np.integer):
        raise ValueError(f"faces must be an (n_t, 3) int array, got {faces.dtype} {faces.shape}")
    T = _coordinates(T, len(faces), "T")
    out = np.empty((len(faces), 3))
    kernel = for_threads(t_barycentric_kernel, threads)
    low = kernel(_coordinates(F, None, "F"), T, unsigned(faces), out)
    return (out, float(low)) if return_min else out


def _coordinates(X, n, name):
    """``X`` as an (n, 3) float64 array (any strides: no copy of a view)."""
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != 3 or (n is not None and X.shape[0] != n):
        raise ValueError(f"{name} must have shape ({n if n is not None else 'n'}, 3), "
                         f"got {X.shape}")
    return X


def _diamond_indices(mesh):
    """(4, n_d) uint64 view of ``mesh.diamonds`` (``t2 = -1`` -> ``kernels.NO_T``)."""
    from .kernels import unsigned

    return unsigned(mesh.diamonds.T)


def _diamond_array(x, shape, name):
    """A per-diamond field of a DiamondGeometry, checked against the mesh."""
    x = np.asarray(x, dtype=np.float64)
    if x.shape != shape:
        raise ValueError(f"geometry field {name} has shape {x.shape}, the mesh needs {shape}")
    return x


def _cross(x, y):
    """Cross product of (3, m) component arrays."""
    return np.stack([x[1] * y[2] - x[2] * y[1],
                     x[2] * y[0] - x[0] * y[2],
                     x[0] * y[1] - x[1] * y[0]])


def _norm(x):
    """Lengths of the columns of a (3, m) component array."""
    return np.sqrt(np.einsum("ij,ij->j", x, x))
