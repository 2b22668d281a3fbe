"""Geometry of the diamond mesh at one time level, vectorized over diamonds.

Notation of the paper (Sections 2.2.3-2.2.5) per diamond ``(a, b, t1, t2)``:
``u = F_b - F_a``, ``v = T_t2 - T_t1``, ``S = (F_a + F_b + T_t1 + T_t2) / 4``,
``J = |u x v| = 2 chi(V^D)``. On a boundary diamond (``t2 = -1``) the
missing T-vertex is the reflection ``F_a + F_b - T_t1`` (end of Section
2.2.5), so ``S`` is the edge midpoint and the cell is the triangle
``F_a, F_b, T_t1`` (see ``ddfv/README.md``).
"""

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class DiamondGeometry:
    """Per-diamond quantities; vectors are stored by components.

    Attributes
    ----------
    u, v : (3, n_d) float arrays
        The diagonals ``F_b - F_a`` and ``T_t2 - T_t1`` (2.3).
    e : (3, n_d) float array
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
    quarters : (4, n_d) float array
        Areas of the triangles ``(F_a, T_t1, S)``, ``(F_a, S, T_t2)``,
        ``(F_b, T_t1, S)``, ``(F_b, S, T_t2)`` that cut the diamond at
        ``S`` (Section 2.2.4), see :func:`covolume_areas`; zero on the
        ``T_t2`` side of boundary diamonds.
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


def diamond_geometry(mesh, F, T, dual_length="broken"):
    """Geometric factors of all diamonds, see :class:`DiamondGeometry`.

    Every length and area follows from the Gram matrix of ``u, v, e``
    (``|x x y|^2 = |x|^2 |y|^2 - (x.y)^2``), which costs far fewer array
    passes than cross products of the corner vectors.

    Parameters
    ----------
    mesh : DiamondMesh
    F : (n_f, 3) float array
    T : (n_t, 3) float array
    dual_length : {"broken", "chord"}
        ``|gamma|`` as the paper's broken line through ``S`` (2.5), or as the
        chord (``|gamma^T| = |v|``, ``|gamma^F| = |u|``).

    Returns
    -------
    DiamondGeometry
    """
    if dual_length not in DUAL_LENGTHS:
        raise ValueError(f"unknown dual_length {dual_length!r}; choose one of "
                         f"{', '.join(DUAL_LENGTHS)}")
    Fa, Fb, T1, T2 = diamond_corners(mesh, F, T)
    u = Fb - Fa
    v = T2 - T1
    e = Fa + Fb
    e -= T1
    e -= T2
    e *= 0.25
    uu, vv, ee = _dot(u, u), _dot(v, v), _dot(e, e)
    uv, ue, ve = _dot(u, v), _dot(u, e), _dot(v, e)
    # squared lengths of F_a - S, F_b - S, T_t1 - S, T_t2 - S
    base_f, base_t = 0.25 * uu + ee, 0.25 * vv + ee
    ra2, rb2, p2, q2 = base_f - ue, base_f + ue, base_t + ve, base_t - ve
    # (F_a - S).(T_t1 - S) etc. for the four quarter triangles at S
    c_minus, c_plus = 0.25 * uv - ee, 0.25 * uv + ee
    d_minus, d_plus = 0.5 * (ue - ve), 0.5 * (ue + ve)
    ra_p, rb_q = c_minus + d_minus, c_minus - d_minus
    ra_q, rb_p = d_plus - c_plus, d_plus + c_plus  # rb_p up to its sign
    quarters = np.empty((4, len(uu)))
    for out, x2, y2, xy in ((quarters[0], ra2, p2, ra_p), (quarters[1], ra2, q2, ra_q),
                            (quarters[2], rb2, p2, rb_p), (quarters[3], rb2, q2, rb_q)):
        np.multiply(x2, y2, out=out)
        out -= xy * xy
    np.maximum(quarters, 0.0, out=quarters)
    np.sqrt(quarters, out=quarters)
    quarters *= 0.5
    if mesh.has_boundary:
        quarters[[1, 3]] *= ~mesh.boundary
    len_u, len_v = np.sqrt(uu), np.sqrt(vv)
    if dual_length == "chord":
        gamma_t, gamma_f = len_v, len_u
    else:
        gamma_t = np.sqrt(p2) + np.sqrt(q2)    # (2.5)
        gamma_f = np.sqrt(ra2) + np.sqrt(rb2)  # (2.15), Section 2.2.5
    return DiamondGeometry(
        u=u, v=v, e=e, len_u=len_u, len_v=len_v,
        J=np.sqrt(np.maximum(0.0, uu * vv - uv**2)), uv=uv,
        gamma_t=gamma_t, gamma_f=gamma_f, quarters=quarters)


def covolume_areas(mesh, geom):
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

    Returns
    -------
    chi_f : (n_f,) float array
    chi_t : (n_t,) float array
    """
    q_a1, q_a2, q_b1, q_b2 = geom.quarters
    a, b, t1, t2 = mesh.diamonds.T
    chi_f = (np.bincount(a, q_a1 + q_a2, minlength=mesh.n_f)
             + np.bincount(b, q_b1 + q_b2, minlength=mesh.n_f))
    inner = ~mesh.boundary
    chi_t = np.bincount(t1, q_a1 + q_b1, minlength=mesh.n_t)
    chi_t += np.bincount(t2[inner], (q_a2 + q_b2)[inner], minlength=mesh.n_t)
    return chi_f, chi_t


def vertex_normals(mesh, geom):
    """Unit normals at F- and T-vertices for the elimination (3.6).

    The normal of a diamond cell is ``u x v / J`` (one orientation for all
    diamonds of a consistently oriented mesh); the normal at a vertex is the
    normalised sum of ``u x v = 2 chi(V^D) N^D`` over the diamonds of its
    covolume, i.e. the area-weighted mean of the diamond normals.

    Returns
    -------
    (3, n_f + n_t) float array
    """
    uxv = _cross(geom.u, geom.v)
    a, b, t1, t2 = mesh.diamonds.T
    inner = ~mesh.boundary
    rows = np.concatenate([a, b, mesh.n_f + t1, mesh.n_f + t2[inner]])
    n = mesh.n_unknowns
    N = np.stack([np.bincount(rows, np.concatenate([c, c, c, c[inner]]), minlength=n)
                  for c in uxv])
    return N / _norm(N)


def triangle_areas(F, faces):
    """(n_t,) areas of the triangles of the primal mesh."""
    p0, p1, p2 = np.take(F.T, faces.T, axis=1).swapaxes(0, 1)
    return 0.5 * _norm(_cross(p1 - p0, p2 - p0))


def t_barycentric(F, T, faces):
    """Barycentric coordinates of each T-vertex projected into its triangle.

    ``(1/3, 1/3, 1/3)`` at the barycentre; a negative coordinate means the
    projection of ``T_i`` has left the triangle (Section 3.2).

    Parameters
    ----------
    F : (n_f, 3) float array
    T : (n_t, 3) float array
    faces : (n_t, 3) int array

    Returns
    -------
    (n_t, 3) float array
    """
    p0, p1, p2 = np.take(F.T, faces.T, axis=1).swapaxes(0, 1)
    e1, e2, d = p1 - p0, p2 - p0, T.T - p0
    # normal equations of the projection onto the plane of the triangle
    g11, g12, g22 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
    r1, r2 = _dot(e1, d), _dot(e2, d)
    det = g11 * g22 - g12**2
    l1 = (g22 * r1 - g12 * r2) / det
    l2 = (g11 * r2 - g12 * r1) / det
    return np.column_stack([1.0 - l1 - l2, l1, l2])


def _cross(x, y):
    """Cross product of (3, m) component arrays."""
    return np.stack([x[1] * y[2] - x[2] * y[1],
                     x[2] * y[0] - x[0] * y[2],
                     x[0] * y[1] - x[1] * y[0]])


def _dot(x, y):
    """Dot products of the columns of (3, m) component arrays."""
    return np.einsum("ij,ij->j", x, y)


def _norm(x):
    return np.sqrt(_dot(x, x))
