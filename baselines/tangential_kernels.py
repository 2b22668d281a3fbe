"""Compiled (numba) kernels of the baselines' tangential motions.

What the schemes that move their vertices along the surface need beyond the
Laplacian (:mod:`baselines.kernels`): the gradient of a P1 function at the
vertices (the redistribution's velocity ``grad psi``,
:mod:`baselines.redistribution`), KLL's gradient-norm weights
(:mod:`baselines.kll`), and the drift of the redistribution: its
Scharfetter-Gummel (Bernoulli) weights and the normal part of the drift
(R5). Apart from :mod:`baselines.kernels` so that each module keeps one
concern: the Laplacian's assembly there, the tangential motions here.
"""

import numpy as np
from numba import njit

from .kernels import add_at_corners


@njit(cache=True)
def vertex_gradients(V, faces, psi, alpha):
    """Gradient of a P1 function at the vertices, lumped L2 projection.

    For the hat-function expansion ``psi = sum_k psi_k phi_k`` the gradient
    on triangle ``t`` is ``grad_t psi = sum_k psi_k grad phi_k`` with
    ``grad phi_k = nu_t x e_k / (2 |t|)``, ``e_k = x_{k+2} - x_{k+1}`` the
    edge opposite corner ``k`` (counter-clockwise about ``nu_t``). Its
    lumped (barycentric) L2 projection onto P1 vectors is the
    area-weighted mean over the triangles at each vertex::

        alpha_i = sum_{t ni i} |t| grad_t psi / sum_{t ni i} |t|
                = sum_t N_t x (sum_k psi_k e_k) / |N_t|  /  sum_t |N_t|

    (``N_t = 2 |t| nu_t``), a combination of tangent vectors of the
    triangles at ``i``, then projected onto the tangent plane of the
    area-weighted vertex normal ``n_i = sum_t N_t / |sum_t N_t|``:
    ``alpha_i - (alpha_i . n_i) n_i``. (Without the projection the mean of
    the tilted triangle gradients has a normal part of order ``h |grad
    psi| / R``, a motion that is not tangential; with it, the field is
    exactly zero at a vertex fixed by a rotation of the mesh about
    ``n_i``.) The tangential velocity ``v_T = grad psi`` of
    :mod:`baselines.redistribution`.

    Parameters
    ----------
    V : (n, 3) float64 array
    faces : (m, 3) int64 array
    psi : (n,) float64 array
    alpha : (n, 3) float64 array, output
        Zero at a vertex whose triangles all have zero area.

    Returns
    -------
    degenerate : int
        Triangles of zero (or non-finite) area, skipped (never a division
        by zero here).
    first : int
        The first of them, ``-1`` if none.
    """
    n = V.shape[0]
    weight = np.zeros(n)
    normal = np.zeros((n, 3))
    alpha[:] = 0.0
    degenerate, first = 0, -1
    for t in range(faces.shape[0]):
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        ax, ay, az = V[i1, 0] - V[i0, 0], V[i1, 1] - V[i0, 1], V[i1, 2] - V[i0, 2]
        bx, by, bz = V[i2, 0] - V[i0, 0], V[i2, 1] - V[i0, 1], V[i2, 2] - V[i0, 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        dbl = np.sqrt(nx * nx + ny * ny + nz * nz)
        if not dbl > 0.0 or not np.isfinite(dbl):
            if first < 0:
                first = t
            degenerate += 1
            continue
        # sum_k psi_k e_k: e_0 = x2 - x1, e_1 = x0 - x2, e_2 = x1 - x0
        p0, p1, p2 = psi[i0], psi[i1], psi[i2]
        ex = p0 * (V[i2, 0] - V[i1, 0]) + p1 * (V[i0, 0] - V[i2, 0]) + p2 * (V[i1, 0] - V[i0, 0])
        ey = p0 * (V[i2, 1] - V[i1, 1]) + p1 * (V[i0, 1] - V[i2, 1]) + p2 * (V[i1, 1] - V[i0, 1])
        ez = p0 * (V[i2, 2] - V[i1, 2]) + p1 * (V[i0, 2] - V[i2, 2]) + p2 * (V[i1, 2] - V[i0, 2])
        # N x E / |N| = 2 |t| grad_t psi
        gx = (ny * ez - nz * ey) / dbl
        gy = (nz * ex - nx * ez) / dbl
        gz = (nx * ey - ny * ex) / dbl
        add_at_corners(faces, t, alpha, gx, gy, gz, weight, dbl)
        for k in range(3):
            i = faces[t, k]
            normal[i, 0] += nx
            normal[i, 1] += ny
            normal[i, 2] += nz
    for i in range(n):
        if not weight[i] > 0.0:
            continue
        ux, uy, uz = normal[i, 0], normal[i, 1], normal[i, 2]
        length = np.sqrt(ux * ux + uy * uy + uz * uz)
        if not length > 0.0:                        # normals cancel: no tangent plane
            alpha[i, 0] = alpha[i, 1] = alpha[i, 2] = 0.0
            continue
        ux, uy, uz = ux / length, uy / length, uz / length
        gx, gy, gz = alpha[i, 0] / weight[i], alpha[i, 1] / weight[i], alpha[i, 2] / weight[i]
        d = gx * ux + gy * uy + gz * uz
        alpha[i, 0], alpha[i, 1], alpha[i, 2] = gx - d * ux, gy - d * uy, gz - d * uz
    return degenerate, first


@njit(cache=True)
def gradient_norm_weights(V, faces, u, w, squared):
    """The lumped ``int |grad u|^2 phi_i`` of a P1 vector field ``u``, one value per triangle.

    On triangle ``t`` with area vector ``N`` and edges ``e_k`` opposite corner ``k``
    (counter-clockwise about ``N``), ``grad phi_k = N x e_k / |N|^2``, so the gradient
    of component ``c`` is ``N x E_c / |N|^2`` with ``E = sum_k u_k (x) e_k`` (3 x 3, its
    rows in the triangle's plane) and ``|grad_t u|^2 = |E|_F^2 / |N|^2``. Then
    ``w_i = sum_{t ni i} |t| |grad_t u|^2 / 3`` (barycentric quadrature). KLL's
    ``|A|^2`` term (:mod:`baselines.kll`, (KL4)).

    Parameters
    ----------
    V : (n, 3) float64 array
    faces : (m, 3) int64 array
    u : (n, 3) float64 array
    w : (n,) float64 array, output
    squared : (m,) float64 array, output
        ``|grad_t u|^2``; 0 on a triangle of zero (or non-finite) area.

    Returns
    -------
    degenerate : int
        Triangles of zero (or non-finite) area, skipped (never a division by zero).
    """
    w[:] = 0.0
    degenerate = 0
    for t in range(faces.shape[0]):
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        ax, ay, az = V[i1, 0] - V[i0, 0], V[i1, 1] - V[i0, 1], V[i1, 2] - V[i0, 2]
        bx, by, bz = V[i2, 0] - V[i0, 0], V[i2, 1] - V[i0, 1], V[i2, 2] - V[i0, 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        dbl2 = nx * nx + ny * ny + nz * nz
        squared[t] = 0.0
        if not (dbl2 > 0.0 and np.isfinite(dbl2)):
            degenerate += 1
            continue
        total = 0.0
        for d in range(3):
            # e_0 = x2 - x1, e_1 = x0 - x2, e_2 = x1 - x0, component d
            e0, e1, e2 = V[i2, d] - V[i1, d], V[i0, d] - V[i2, d], V[i1, d] - V[i0, d]
            for c in range(3):
                E = u[i0, c] * e0 + u[i1, c] * e1 + u[i2, c] * e2
                total += E * E
        squared[t] = total / dbl2
        share = squared[t] * np.sqrt(dbl2) / 6.0
        w[i0] += share
        w[i1] += share
        w[i2] += share
    return degenerate


@njit(cache=True, inline="always")
def bernoulli_weight(x):
    """``B(x) = x / (e^x - 1)``, ``B(0) = 1``: the Scharfetter-Gummel weight of (R4)
    (:func:`baselines.redistribution.drift_laplacian`), positive, ``-> -x`` for ``x ->
    -inf`` and ``-> 0`` for ``x -> +inf`` (no overflow), ``B(-x) = B(x) + x``. For
    ``|x| < 0.1`` (every weight under the default Peclet limit) its Taylor series ``sum
    B_k x^k / k!`` to ``x^8``: the next term is below 2.1e-18, so the value is that of
    ``expm1`` to rounding (measured: 2.2e-16 relative against ``tests/reference.py``),
    at a third of its cost."""
    if abs(x) < 0.1:
        x2 = x * x
        return 1.0 - 0.5 * x + x2 * (1.0 / 12.0 + x2 * (-1.0 / 720.0 + x2 * (
            1.0 / 30240.0 - x2 / 1209600.0)))
    return x / np.expm1(x)


@njit(cache=True, inline="always")
def _drift_row(indptr, indices, L_data, psi, peclet, X, i, out):
    """Row ``i`` of :func:`drift_weights`: its off-diagonal values written into ``out``;
    returns ``(minus their sum, the diagonal's position or -1, ((L_psi - L) X)_i)``."""
    total = 0.0
    diagonal = -1
    d0 = d1 = d2 = 0.0
    for p in range(indptr[i], indptr[i + 1]):
        j = indices[p]
        if j == i:
            diagonal = p
            continue
        x = min(max(psi[i] - psi[j], -peclet), peclet)
        w = L_data[p] * bernoulli_weight(x)
        out[p] = w
        total += w
        c = w - L_data[p]
        d0 += c * (X[0, j] - X[0, i])
        d1 += c * (X[1, j] - X[1, i])
        d2 += c * (X[2, j] - X[2, i])
    return -total, diagonal, d0, d1, d2


@njit(cache=True)
def drift_weights(indptr, indices, L_data, psi, peclet, X, out, DX):
    """Values of the drift stiffness (R4) of :mod:`baselines.redistribution` in the
    pattern of ``L``: off-diagonal ``L_ij B(psi_i - psi_j)``, the difference clipped
    to ``[-peclet, peclet]``, ``B(x) = x / (e^x - 1)`` (``B(0) = 1``), and the
    diagonal minus the sum of its row's off-diagonal values (zero row sums); in the
    same pass ``(L_psi - L) X`` (the drift of (R5)), as ``sum_j (L_psi - L)_ij (X_j -
    X_i)`` (both matrices have zero row sums).

    Parameters
    ----------
    indptr : (n + 1,) int array
    indices : (nnz,) int array
        Each row's diagonal stored (it is overwritten).
    L_data : (nnz,) float64 array
        Zero row sums.
    psi : (n,) float64 array
    peclet : float
    X : (3, n) float64 array
    out : (nnz,) float64 array, output
    DX : (3, n) float64 array, output
        ``(L_psi - L) X``.
    """
    for i in range(len(indptr) - 1):
        diagonal_value, diagonal, d0, d1, d2 = _drift_row(indptr, indices, L_data, psi,
                                                          peclet, X, i, out)
        if diagonal >= 0:
            out[diagonal] = diagonal_value
        DX[0, i], DX[1, i], DX[2, i] = d0, d1, d2


@njit(cache=True)
def drifted_system(indptr, indices, L_data, diag_slots, psi, peclet, X, omega, mass, tau,
                   fixed, base, A_data, rhs):
    """The system of a redistributing cotangent step in one pass over the rows of ``L``:
    the values of ``I + tau diag(1/m) L_psi`` ((C3) of :mod:`baselines.cotan` with the
    drift stiffness (R4), :func:`drift_weights`) and ``rhs = base + tau g`` with ``g``
    the normal part (R5) of the drift (:func:`normal_parts`), the numbers of
    :func:`drift_weights`, :func:`baselines.kernels.row_scaled_system` and
    :func:`normal_parts` bit for bit without their arrays ``L_psi`` and ``(L_psi - L)
    X`` and two more passes. Rows ``fixed`` or of zero mass: identity, ``rhs = base``.

    Parameters
    ----------
    indptr, indices : CSR pattern of ``L`` (n, n), each row's diagonal stored
    L_data : (nnz,) float64 array
    diag_slots : (n,) int array
    psi : (n,) float64 array
    peclet : float
    X : (3, n) float64 array
        The state of ``L`` (its drift is the normal part's).
    omega : (n, 3) float64 array
        Vertex normals, any length (:func:`baselines.kernels.vertex_normals`).
    mass : (n,) float64 array
    tau : float
    fixed : (n,) bool array
    base : (3, n) float64 array
    A_data : (nnz,) float64 array, output
    rhs : (3, n) float64 array, output
    """
    for i in range(len(indptr) - 1):
        lo, hi = indptr[i], indptr[i + 1]
        if fixed[i] or not mass[i] > 0.0:
            for p in range(lo, hi):
                A_data[p] = 0.0
            A_data[diag_slots[i]] = 1.0
            rhs[0, i], rhs[1, i], rhs[2, i] = base[0, i], base[1, i], base[2, i]
            continue
        diagonal_value, diagonal, d0, d1, d2 = _drift_row(indptr, indices, L_data, psi,
                                                          peclet, X, i, A_data)
        if diagonal >= 0:
            A_data[diagonal] = diagonal_value
        s = tau / mass[i]
        for p in range(lo, hi):
            A_data[p] = A_data[p] * s
        A_data[diag_slots[i]] += 1.0
        g = _normal_part(omega, d0, d1, d2, mass, fixed, i)
        rhs[0, i] = base[0, i] + tau * (g * omega[i, 0])
        rhs[1, i] = base[1, i] + tau * (g * omega[i, 1])
        rhs[2, i] = base[2, i] + tau * (g * omega[i, 2])


@njit(cache=True)
def squared_curvature_normals(indptr, indices, data, X, mass, fixed, out):
    """``out_i = |(L X)_i|^2 / m_i^2``, the ``|h_i|^2`` of the redistribution's source
    (R2) (:func:`baselines.redistribution.redistribution_source`), in one pass over the
    rows of ``L`` (each row's products summed in storage order, as scipy's product);
    zero at fixed vertices and where ``m_i <= 0``.

    Parameters
    ----------
    indptr, indices, data : CSR arrays of ``L`` (n, n)
    X : (3, n) float64 array
    mass : (n,) float64 array
    fixed : (n,) bool array
    out : (n,) float64 array, output
    """
    for i in range(mass.shape[0]):
        y0 = y1 = y2 = 0.0
        for p in range(indptr[i], indptr[i + 1]):
            j, a = indices[p], data[p]
            y0 += a * X[0, j]
            y1 += a * X[1, j]
            y2 += a * X[2, j]
        m = mass[i]
        out[i] = 0.0 if fixed[i] or not m > 0.0 else ((y0 * y0 + y1 * y1) + y2 * y2) / (m * m)


@njit(cache=True, inline="always")
def _normal_part(omega, d0, d1, d2, mass, fixed, i):
    """``s`` with ``g_i = s omega_i`` in :func:`normal_parts`, from ``D_i = (d0, d1, d2)``."""
    nx, ny, nz = omega[i, 0], omega[i, 1], omega[i, 2]
    squared = nx * nx + ny * ny + nz * nz
    if not fixed[i] and squared > 0.0 and mass[i] > 0.0:
        return (nx * d0 + ny * d1 + nz * d2) / (squared * mass[i])
    return 0.0


@njit(cache=True)
def normal_parts(omega, D, mass, fixed, g):
    """``g_i = N_i N_i . D_i / m_i`` (the normal part (R5) of the drift of
    :mod:`baselines.redistribution`), ``N_i = omega_i / |omega_i|``; zero at fixed
    vertices and where ``omega_i = 0`` or ``m_i <= 0``.

    Parameters
    ----------
    omega : (n, 3) float64 array
        Vertex normals, any length (:func:`baselines.kernels.vertex_normals`).
    D : (3, n) float64 array
    mass : (n,) float64 array
    fixed : (n,) bool array
    g : (3, n) float64 array, output
    """
    for i in range(mass.shape[0]):
        s = _normal_part(omega, D[0, i], D[1, i], D[2, i], mass, fixed, i)
        g[0, i], g[1, i], g[2, i] = s * omega[i, 0], s * omega[i, 1], s * omega[i, 2]
