"""Compiled (numba) kernels of the tangential motions of a step: (TM1)-(TM4), the
carried T-vertices, the right-hand side of the elimination (3.6), and the
redistribution's ``h.V`` and the sweeps of its potential's start.

The formulas are those of :mod:`ddfv.tangential_motion`,
:func:`ddfv.redistribution.carry_t_vertices` and :meth:`ddfv.flow.Flow.system`,
which call these kernels and document the results; each kernel does in one loop
what numpy did in a chain of gathers, sparse products, ``einsum``, ``cross`` and
norms over ``(n, 3)`` arrays, with the same operations in the same order (the
results are numpy's, bit for bit: tested). The conventions of :mod:`ddfv.kernels`
hold (explicit signatures, layout ``A`` for coordinates, unsigned ``uint64``
indices checked against their arrays, ``cache=True``); like it, this module is
imported on first use only.
"""

import numba
import numpy as np

from .kernels import _OPTIONS, unsigned


@numba.njit("float64(float64, float64, float64, float64, float64, float64)", **_OPTIONS,
            inline="always")
def _dot(x0, x1, x2, y0, y1, y2):
    """``x . y`` summed as numpy's ``einsum("ij,ij->i")`` sums three terms of contiguous
    rows, ``(x0 y0 + x2 y2) + x1 y1`` (in order for strided ones): the kernels give the
    numpy path's numbers bit for bit."""
    return (x0 * y0 + x2 * y2) + x1 * y1


@numba.njit("UniTuple(float64, 3)(float64, float64, float64, float64, float64, float64)",
            **_OPTIONS, inline="always")
def _cross(x0, x1, x2, y0, y1, y2):
    """``x x y``, each component as ``np.cross`` forms it."""
    return x1 * y2 - x2 * y1, x2 * y0 - x0 * y2, x0 * y1 - x1 * y0


@numba.njit("void(float64[:, :], uint64[:, :], float64[:, ::1])", **_OPTIONS)
def half_cotangents_kernel(F, faces, out):
    """``out[k, t] = cot(angle_k) / 2`` at corner ``k`` of triangle ``t``
    (:func:`ddfv.tangential_motion.half_cotangents`).

    Parameters
    ----------
    F : (n, 3) float64 array
    faces : (m, 3) uint64 array
    out : (3, m) float64 array, output
    """
    n = np.uint64(F.shape[0])
    bad = 0
    for t in range(faces.shape[0]):
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        if i0 >= n or i1 >= n or i2 >= n:
            bad += 1
            continue
        e0x, e0y, e0z = F[i2, 0] - F[i1, 0], F[i2, 1] - F[i1, 1], F[i2, 2] - F[i1, 2]
        e1x, e1y, e1z = F[i0, 0] - F[i2, 0], F[i0, 1] - F[i2, 1], F[i0, 2] - F[i2, 2]
        e2x, e2y, e2z = F[i1, 0] - F[i0, 0], F[i1, 1] - F[i0, 1], F[i1, 2] - F[i0, 2]
        cx, cy, cz = _cross(e1x, e1y, e1z, e2x, e2y, e2z)       # e_1 x e_2 = 2 |t| n
        scale = -2.0 * np.sqrt(_dot(cx, cy, cz, cx, cy, cz))
        out[0, t] = _dot(e1x, e1y, e1z, e2x, e2y, e2z) / scale
        out[1, t] = _dot(e2x, e2y, e2z, e0x, e0y, e0z) / scale
        out[2, t] = _dot(e0x, e0y, e0z, e1x, e1y, e1z) / scale
    if bad > 0:
        raise IndexError("face index out of range")


@numba.njit("void(int32[::1], int32[::1], float64[::1], float64[:, :], float64[:, :], "
            "uint64[::1], float64[::1], float64[:, ::1], float64[::1])", **_OPTIONS)
def tangent_product_kernel(indptr, indices, data, t1, t2, rows, s, D, out):
    """``out = S s = E^T A E s`` of (TM2) without ``S``
    (:meth:`ddfv.tangential_motion.TangentialMotion._operator`).

    Parameters
    ----------
    indptr, indices, data : int32, int32, float64 arrays
        ``A`` (n, n) in CSR, sorted or not.
    t1, t2 : (n_free, 3) float64 arrays
        Tangent bases at the free vertices.
    rows : (n_free,) uint64 array
        The vertex of each free unknown pair.
    s : (2 n_free,) float64 array
        Interleaved, ``(k, a) -> 2 k + a``.
    D : (n, 3) float64 array, work space
        Zero at the fixed vertices (its free rows are overwritten by ``E s``).
    out : (2 n_free,) float64 array, output
    """
    n = np.uint64(D.shape[0])
    for i in range(rows.shape[0]):
        if rows[i] >= n:
            raise IndexError("vertex index out of range")
        for c in range(3):                                      # (E s)_k
            D[rows[i], c] = s[2 * i] * t1[i, c] + s[2 * i + 1] * t2[i, c]
    for i in range(rows.shape[0]):
        k = rows[i]
        y0 = y1 = y2 = 0.0                                      # (A E s)_k
        for p in range(indptr[k], indptr[k + 1]):
            j, a = indices[p], data[p]
            y0 += a * D[j, 0]
            y1 += a * D[j, 1]
            y2 += a * D[j, 2]
        out[2 * i] = _dot(t1[i, 0], t1[i, 1], t1[i, 2], y0, y1, y2)
        out[2 * i + 1] = _dot(t2[i, 0], t2[i, 1], t2[i, 2], y0, y1, y2)


@numba.njit("int64(float64[:, :], float64[:, :], float64[:, ::1], float64[:, ::1], "
            "boolean[::1])", **_OPTIONS)
def follow_bases_kernel(t1_old, N, t1, t2, short):
    """``t1`` the last ``t1_old`` projected on the tangent planes of ``N`` and normalised,
    ``t2 = N x t1`` (:meth:`ddfv.tangential_motion.TangentialMotion._bases`); where the
    projection is not longer than 1/2, ``short`` is set and ``t1``, ``t2`` are left for
    the caller. Returns the number of short rows.

    Parameters
    ----------
    t1_old, N : (n, 3) float64 arrays
    t1, t2 : (n, 3) float64 arrays, output
    short : (n,) bool array, output
    """
    count = 0
    for i in range(N.shape[0]):
        # in order, as numpy's einsum sums with a strided N (the flow's normals, a view)
        d = t1_old[i, 0] * N[i, 0] + t1_old[i, 1] * N[i, 1] + t1_old[i, 2] * N[i, 2]
        p0 = t1_old[i, 0] - d * N[i, 0]
        p1 = t1_old[i, 1] - d * N[i, 1]
        p2 = t1_old[i, 2] - d * N[i, 2]
        length = np.sqrt(p0 * p0 + p1 * p1 + p2 * p2)
        short[i] = length <= 0.5
        if short[i]:
            count += 1
            continue
        p0, p1, p2 = p0 / length, p1 / length, p2 / length
        t1[i, 0], t1[i, 1], t1[i, 2] = p0, p1, p2
        t2[i, 0], t2[i, 1], t2[i, 2] = _cross(N[i, 0], N[i, 1], N[i, 2], p0, p1, p2)
    return count


@numba.njit("void(float64[:, :], float64[:, :], uint64[:, :], float64[:, :], boolean, "
            "float64[:, :])", **_OPTIONS)
def t_vertices_kernel(F, T, faces, lam, carry, out):
    """The T-vertices moved with their triangles: ``carry`` False, ``out = T + sum_k
    lam_k F_k`` (``F`` the F-vertices' displacement; (TM4),
    :func:`ddfv.tangential_motion.follow_triangles`); ``carry`` True, ``out = Q + ((T -
    Q) . n) n``, ``Q = sum_k lam_k F_k``, ``n`` the unit normal of the triangle
    (:func:`ddfv.redistribution.carry_t_vertices`).

    Parameters
    ----------
    F : (n_f, 3) float64 array
    T : (n_t, 3) float64 array
    faces : (n_t, 3) uint64 array
    lam : (n_t, 3) float64 array
    carry : bool
    out : (n_t, 3) float64 array, output (may be ``T``)
    """
    n_f = np.uint64(F.shape[0])
    bad = 0
    for t in range(faces.shape[0]):
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        if i0 >= n_f or i1 >= n_f or i2 >= n_f:
            bad += 1
            continue
        l0, l1, l2 = lam[t, 0], lam[t, 1], lam[t, 2]
        qx = l0 * F[i0, 0] + l1 * F[i1, 0] + l2 * F[i2, 0]
        qy = l0 * F[i0, 1] + l1 * F[i1, 1] + l2 * F[i2, 1]
        qz = l0 * F[i0, 2] + l1 * F[i1, 2] + l2 * F[i2, 2]
        if not carry:
            out[t, 0], out[t, 1], out[t, 2] = T[t, 0] + qx, T[t, 1] + qy, T[t, 2] + qz
            continue
        e1x, e1y, e1z = F[i1, 0] - F[i0, 0], F[i1, 1] - F[i0, 1], F[i1, 2] - F[i0, 2]
        e2x, e2y, e2z = F[i2, 0] - F[i0, 0], F[i2, 1] - F[i0, 1], F[i2, 2] - F[i0, 2]
        nx, ny, nz = _cross(e1x, e1y, e1z, e2x, e2y, e2z)
        length = np.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx / length, ny / length, nz / length
        h = _dot(T[t, 0] - qx, T[t, 1] - qy, T[t, 2] - qz, nx, ny, nz)
        out[t, 0], out[t, 1], out[t, 2] = qx + h * nx, qy + h * ny, qz + h * nz
    if bad > 0:
        raise IndexError("face index out of range")


@numba.njit("UniTuple(float64, 3)(int32[::1], int32[::1], float64[::1], float64[:, :], "
            "int64)", **_OPTIONS, inline="always")
def _row_product(indptr, indices, data, X, i):
    """``(A X)_i`` of a (3, n) ``X``, each row's products summed in storage order from 0
    (as scipy's product sums them)."""
    y0 = y1 = y2 = 0.0
    for p in range(indptr[i], indptr[i + 1]):
        j, a = indices[p], data[p]
        y0 += a * X[0, j]
        y1 += a * X[1, j]
        y2 += a * X[2, j]
    return y0, y1, y2


@numba.njit("void(int32[::1], int32[::1], float64[::1], float64[:, :], float64[:, :], "
            "float64[:, :], float64, float64[:, ::1])", **_OPTIONS)
def eliminated_kernel(indptr, indices, data, X, B, N, dt, out):
    """The right-hand side of the elimination (3.6), ``out = B - dt (h - (h.N) N)``
    with ``h = (X - A X) / dt`` (:meth:`ddfv.flow.Flow.system`), in one pass over the
    rows of ``A``: numpy's ``(A @ X.T).T`` (scipy sums each row's products in storage
    order from 0), ``(h * N).sum(axis=0)`` (the components in order) and the
    elementwise arithmetic, bit for bit.

    Parameters
    ----------
    indptr, indices, data : int32, int32, float64 arrays
        ``A`` (n, n) in CSR (the assembler's: its column indices are in range by
        construction and not checked here).
    X, B, N : (3, n) float64 arrays
        The state of the operators ``X*``, the base ``B`` and the unit vertex normals.
    dt : float
    out : (3, n) float64 array, output
    """
    n = X.shape[1]
    if indptr.shape[0] != n + 1 or B.shape[1] != n or N.shape[1] != n or out.shape[1] != n:
        raise ValueError("the matrix, states, normals and output do not fit")
    for i in range(n):
        y0, y1, y2 = _row_product(indptr, indices, data, X, i)  # (A X)_i
        h0, h1, h2 = (X[0, i] - y0) / dt, (X[1, i] - y1) / dt, (X[2, i] - y2) / dt
        hN = (h0 * N[0, i] + h1 * N[1, i]) + h2 * N[2, i]
        out[0, i] = B[0, i] - dt * (h0 - hN * N[0, i])
        out[1, i] = B[1, i] - dt * (h1 - hN * N[1, i])
        out[2, i] = B[2, i] - dt * (h2 - hN * N[2, i])


@numba.njit(**_OPTIONS, inline="always")
def _off_diagonal_run(indices, data, X, lo, hi, c, K_data, y0, y1, y2, total):
    """Entries ``lo:hi`` of a row of :func:`squared_normal_speed_kernel` (none its
    diagonal): their products with ``X`` added to ``y0, y1, y2`` in storage order and,
    when ``K_data`` is not empty, ``c`` times their values written to it and added to
    ``total``; returns ``(y0, y1, y2, total)``."""
    stiffness = K_data.shape[0] > 0
    for p in range(lo, hi):
        j, a = indices[p], data[p]
        y0 += a * X[0, j]
        y1 += a * X[1, j]
        y2 += a * X[2, j]
        if stiffness:
            K_data[p] = c * a
            total += K_data[p]
    return y0, y1, y2, total


@numba.njit("void(int32[::1], int32[::1], float64[::1], uint32[::1], float64[:, :], "
            "float64[:, :], float64, float64[::1], float64[::1], float64[::1])", **_OPTIONS)
def squared_normal_speed_kernel(indptr, indices, data, diagonal, X, N, dt, chi, out, K_data):
    """``out = (h . N)^2`` with ``h = (X - A X) / dt``, the ``h . V = H^2`` of the
    redistribution's source (R3) (:meth:`ddfv.flow.Flow._potential_of`), in one pass
    over the rows of ``A`` (the products summed in storage order, as scipy's; the dot
    product with ``N`` in the order of the components: numpy's ``einsum`` may sum it
    otherwise, by an ulp); in the same pass, when ``K_data`` is not empty, the values
    of the stiffness ``K`` of ``A = I + dt diag(1/chi) K`` in ``A``'s pattern
    (:func:`ddfv.redistribution.potential_operators`: a closed surface, no
    Dirichlet row): off the diagonal ``(chi_i / dt) A_ij``, on it minus the sum of the
    row's others in storage order (``K``'s rows sum to zero; the ``1`` of ``A_ii`` is
    never subtracted). Each row is read in three runs, before, at and after its
    diagonal (no comparison per entry: 0.26 ms against 0.50 ms for the ``K`` part at
    level 5 of the sphere, 276 482 entries).

    Parameters
    ----------
    indptr, indices, data : int32, int32, float64 arrays
        ``A`` (n, n) in CSR (the assembler's: its column indices are in range by
        construction and not checked here).
    diagonal : (n,) uint32 array
        The position of each row's diagonal entry in ``data``.
    X, N : (3, n) float64 arrays
        The state of the operators ``X*`` and the unit vertex normals.
    dt : float
    chi : (n,) float64 array
        The covolume areas of ``A``'s rows (read only for ``K_data``).
    out : (n,) float64 array, output
    K_data : (nnz,) or (0,) float64 array, output
    """
    n = X.shape[1]
    if (indptr.shape[0] != n + 1 or N.shape[1] != n or out.shape[0] != n
            or diagonal.shape[0] != n):
        raise ValueError("the matrix, its diagonal, state, normals and output do not fit")
    stiffness = K_data.shape[0] > 0
    if stiffness and (K_data.shape[0] != data.shape[0] or chi.shape[0] != n):
        raise ValueError("the stiffness's values or the covolumes do not fit the matrix")
    for i in range(n):
        d = np.int64(diagonal[i])
        if not indptr[i] <= d < indptr[i + 1] or indices[d] != i:
            raise ValueError("a diagonal position is not its row's diagonal entry")
        c = chi[i] / dt if stiffness else 0.0
        y0, y1, y2, total = _off_diagonal_run(indices, data, X, indptr[i], d, c, K_data,
                                              0.0, 0.0, 0.0, 0.0)  # (A X)_i in storage order
        a = data[d]
        y0, y1, y2 = y0 + a * X[0, i], y1 + a * X[1, i], y2 + a * X[2, i]
        y0, y1, y2, total = _off_diagonal_run(indices, data, X, d + 1, indptr[i + 1], c, K_data,
                                              y0, y1, y2, total)
        if stiffness:
            K_data[d] = -total
        hN = (((X[0, i] - y0) / dt) * N[0, i] + ((X[1, i] - y1) / dt) * N[1, i]) \
            + ((X[2, i] - y2) / dt) * N[2, i]
        out[i] = hN * hN


@numba.njit("float64(int32[::1], int32[::1], float64[::1], float64[::1], float64[::1], "
            "float64[::1], int64, int64)", **_OPTIONS)
def pinned_gauss_seidel_kernel(indptr, indices, data, keep, b, x, lo, hi):
    """One forward Gauss-Seidel sweep over the rows ``lo:hi`` of the pinned system
    ``A = P K P + I - P``, ``P = diag(keep)`` (:func:`kept_factor.pinned`), ``x`` updated
    in place: for each kept row ``i`` in order, ``x_i = (b_i - sum_{j != i} K_ij keep_j
    x_j) / K_ii`` with the values already updated (Saad, Iterative Methods for Sparse
    Linear Systems, 2nd ed., SIAM 2003, Section 4.1, (4.6)); pinned rows (``keep_i =
    0``) are left alone. The start's smoothing of
    :class:`ddfv.redistribution.TangentialPotential`.

    Parameters
    ----------
    indptr, indices, data : int32, int32, float64 arrays
        ``K`` (n, n) in CSR, a nonzero diagonal entry in every kept row of ``lo:hi``
        (its column indices are in range by construction and not checked here).
    keep : (n,) float64 array
        1 where kept, 0 where pinned.
    b : (n,) float64 array
    x : (n,) float64 array, updated
    lo, hi : int
        ``0 <= lo <= hi <= n``.

    Returns
    -------
    float
        ``sum_i r_i^2`` of the residuals ``r_i = b_i - (A x)_i`` of the kept rows, each
        taken just before its row's update (the residual of the sweep's start where no
        earlier row of the sweep changed a value it reads).
    """
    n = x.shape[0]
    if indptr.shape[0] != n + 1 or keep.shape[0] != n or b.shape[0] != n:
        raise ValueError("the matrix, mask, right-hand side and iterate do not fit")
    if not 0 <= lo <= hi <= n:
        raise ValueError("the rows of the sweep are not within the matrix")
    squares = 0.0
    for i in range(lo, hi):
        if keep[i] == 0.0:
            continue
        s, diagonal = b[i], 0.0
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            if j == i:
                diagonal = data[p]
            else:
                s -= data[p] * keep[j] * x[j]
        if diagonal == 0.0:
            raise ValueError("a kept row of the sweep has no diagonal entry")
        r = s - diagonal * x[i]
        squares += r * r
        x[i] = s / diagonal
    return squares


def moved_t_vertices(F, T, faces, lam, carry):
    """(n_t, 3) :func:`t_vertices_kernel` of any arrays: ``F`` (n_f, 3), ``T`` (n_t,
    3), ``faces`` (n_t, 3) int, ``lam`` (n_t, 3), ``carry`` bool (views are not copied;
    a face index out of range, also a negative one, raises ``IndexError``)."""
    T = np.asarray(T, dtype=np.float64)
    out = np.empty(T.shape)
    t_vertices_kernel(np.asarray(F, dtype=np.float64), T, unsigned(faces),
                      np.asarray(lam, dtype=np.float64), carry, out)
    return out
