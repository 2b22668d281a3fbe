"""Compiled (numba) assembly kernels of the vertex baselines.

One loop over the triangles computes everything a step of the cotangent
(:mod:`baselines.cotan`), conformalized (:mod:`baselines.cmcf`) and BGN
(:mod:`baselines.bgn`) schemes needs from the current surface, and writes
it straight into arrays laid out by a cached CSR pattern
(:func:`baselines.mesh.laplacian_pattern`); small loops over the rows then
write the system matrices. This puts the baselines on the same footing as
the compiled DDFV assembly: the time of a step is that of the scheme, not
of scipy's sparse-matrix construction. ``neighbour_cosines`` is the
compiled check of :meth:`baselines.vertex_flow.VertexFlow.defects`.

Formulas
--------
For triangle ``t = (x_0, x_1, x_2)`` with edge vectors ``e_k`` opposite
corner ``k`` and area vector ``N = (x_1 - x_0) x (x_2 - x_0)``:

* ``2|t| = |N|``;
* cotangent of the angle at corner ``k``, with ``u, v`` the two edges
  leaving it: ``cot_k = (u . v) / |u x v| = (u . v) / |N|``;
* stiffness ``L_ij = -1/2 (cot alpha_ij + cot beta_ij)`` for an edge,
  ``L_ii = -sum_j L_ij``: the P1 stiffness matrix ``int grad phi_i . grad
  phi_j`` (Dziuk 1991; the cotangent formula of Pinkall and Polthier 1993;
  libigl ``cotmatrix`` with the opposite sign): each triangle adds
  ``cot_k / 2`` to the edge opposite corner ``k``;
* barycentric lumped mass ``m_i = sum_{t ni i} |t| / 3``;
* Voronoi (mixed) mass (Meyer, Desbrun, Schroeder, Barr 2003, Section 3.3
  and Fig. 4): the Voronoi area ``(|e_j|^2 cot_j + |e_k|^2 cot_k) / 8`` of
  corner ``i`` in a non-obtuse triangle, ``|t|/2`` at an obtuse corner and
  ``|t|/4`` at the other two corners of an obtuse triangle. Computed as
  libigl's ``massmatrix`` does (circumcentre barycentric coordinates
  ``cos_k |e_k|``, normalised, times ``|t|``; the quad of corner ``i`` is
  half the sum of the two sub-triangles adjacent to it), so the two agree
  to rounding.
"""

import numpy as np
from numba import njit, prange


@njit(cache=True)
def cotan_geometry(V, faces, corner_slots, diag_slots, voronoi, with_laplacian,
                   L_data, mass, area_vectors):
    """Cotangent stiffness, lumped mass and area vectors of one surface.

    Parameters
    ----------
    V : (n, 3) float64 array
        Vertices (any layout; :meth:`baselines.laplacian.CotanAssembler.geometry`
        passes Fortran order).
    faces : (m, 3) int64 array
    corner_slots : (m, 3, 2) int64 array
        CSR positions of ``(i, j)`` and ``(j, i)`` for the edge opposite each
        corner (:class:`baselines.mesh.LaplacianPattern`).
    diag_slots : (n,) int64 array
    voronoi : bool
        Voronoi (mixed) mass instead of barycentric.
    with_laplacian : bool
        Fill ``L_data`` (False: only the mass and the area vectors).
    L_data : (nnz,) float64 array, output
        Values of the stiffness ``L`` (positive semi-definite) in the pattern.
    mass : (n,) float64 array, output
        Lumped mass ``m_i``.
    area_vectors : (m, 3) float64 array, output
        ``N_t``; ``|N_t| = 2 |t|``.

    Returns
    -------
    degenerate : int
        Number of triangles with ``|N_t| = 0`` (or not finite). They add
        nothing to ``L`` or the mass (their cotangents are undefined); the
        caller reports them (never a division by zero here).
    first : int
        The first such triangle, ``-1`` if none.
    """
    m = faces.shape[0]
    if with_laplacian:
        L_data[:] = 0.0
    mass[:] = 0.0
    degenerate, first = 0, -1
    for t in range(m):
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        # edges leaving each corner: corner 0: u0 = x1 - x0, v0 = x2 - x0
        ax, ay, az = V[i1, 0] - V[i0, 0], V[i1, 1] - V[i0, 1], V[i1, 2] - V[i0, 2]
        bx, by, bz = V[i2, 0] - V[i0, 0], V[i2, 1] - V[i0, 1], V[i2, 2] - V[i0, 2]
        cx, cy, cz = V[i2, 0] - V[i1, 0], V[i2, 1] - V[i1, 1], V[i2, 2] - V[i1, 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        area_vectors[t, 0], area_vectors[t, 1], area_vectors[t, 2] = nx, ny, nz
        dbl = np.sqrt(nx * nx + ny * ny + nz * nz)              # 2 |t|
        if not dbl > 0.0 or not np.isfinite(dbl):                 # zero area or NaN: no cotangents
            if first < 0:
                first = t
            degenerate += 1
            continue
        # u.v at each corner: 0: (x1-x0).(x2-x0); 1: (x2-x1).(x0-x1); 2: (x0-x2).(x1-x2)
        d0 = ax * bx + ay * by + az * bz
        d1 = -(cx * ax + cy * ay + cz * az)
        d2 = cx * bx + cy * by + cz * bz
        if with_laplacian:
            for k, d in ((0, d0), (1, d1), (2, d2)):
                w = 0.5 * d / dbl                               # cot_k / 2
                L_data[corner_slots[t, k, 0]] -= w
                L_data[corner_slots[t, k, 1]] -= w
                L_data[diag_slots[faces[t, (k + 1) % 3]]] += w
                L_data[diag_slots[faces[t, (k + 2) % 3]]] += w
        if not voronoi:
            third = dbl / 6.0
            mass[i0] += third
            mass[i1] += third
            mass[i2] += third
            continue
        # squared edge lengths opposite each corner
        s0 = cx * cx + cy * cy + cz * cz
        s1 = bx * bx + by * by + bz * bz
        s2 = ax * ax + ay * ay + az * az
        if d0 < 0.0:
            mass[i0] += 0.25 * dbl
            mass[i1] += 0.125 * dbl
            mass[i2] += 0.125 * dbl
        elif d1 < 0.0:
            mass[i0] += 0.125 * dbl
            mass[i1] += 0.25 * dbl
            mass[i2] += 0.125 * dbl
        elif d2 < 0.0:
            mass[i0] += 0.125 * dbl
            mass[i1] += 0.125 * dbl
            mass[i2] += 0.25 * dbl
        else:
            # Voronoi area of corner i: (|e_j|^2 cot_j + |e_k|^2 cot_k) / 8
            c0, c1, c2 = d0 / dbl, d1 / dbl, d2 / dbl
            mass[i0] += (s1 * c1 + s2 * c2) / 8.0
            mass[i1] += (s2 * c2 + s0 * c0) / 8.0
            mass[i2] += (s0 * c0 + s1 * c1) / 8.0
    return degenerate, first


@njit(cache=True)
def triangle_terms(V, faces, voronoi, half_cot, corner_mass, area_vectors, live):
    """What each triangle adds in :func:`cotan_geometry`, kept per triangle for
    :func:`gather_geometry` (the two passes of a threaded assembly: no two threads
    add into one vertex's entries).

    Parameters
    ----------
    V : (n, 3) float64 array
    faces : (m, 3) int64 array
    voronoi : bool
    half_cot : (m, 3) float64 array, output
        ``cot_k / 2`` at each corner (the weight of the edge opposite it).
    corner_mass : (m, 3) float64 array, output
        The lumped mass the triangle gives each corner (barycentric or Voronoi).
    area_vectors : (m, 3) float64 array, output
    live : (m,) bool array, output
        False for a triangle with ``|N_t| = 0`` or not finite (it adds nothing).

    Returns
    -------
    degenerate, first : int
        As :func:`cotan_geometry` (``first = m`` read as ``-1`` by the caller).
    """
    m = faces.shape[0]
    degenerate = 0
    first = m
    for t in prange(m):                   # triangles apart
        i0, i1, i2 = faces[t, 0], faces[t, 1], faces[t, 2]
        ax, ay, az = V[i1, 0] - V[i0, 0], V[i1, 1] - V[i0, 1], V[i1, 2] - V[i0, 2]
        bx, by, bz = V[i2, 0] - V[i0, 0], V[i2, 1] - V[i0, 1], V[i2, 2] - V[i0, 2]
        cx, cy, cz = V[i2, 0] - V[i1, 0], V[i2, 1] - V[i1, 1], V[i2, 2] - V[i1, 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        area_vectors[t, 0], area_vectors[t, 1], area_vectors[t, 2] = nx, ny, nz
        dbl = np.sqrt(nx * nx + ny * ny + nz * nz)
        ok = dbl > 0.0 and np.isfinite(dbl)
        live[t] = ok
        if not ok:
            degenerate += 1
            first = min(first, t)
            continue
        d0 = ax * bx + ay * by + az * bz
        d1 = -(cx * ax + cy * ay + cz * az)
        d2 = cx * bx + cy * by + cz * bz
        half_cot[t, 0] = 0.5 * d0 / dbl
        half_cot[t, 1] = 0.5 * d1 / dbl
        half_cot[t, 2] = 0.5 * d2 / dbl
        if not voronoi:
            third = dbl / 6.0
            corner_mass[t, 0] = corner_mass[t, 1] = corner_mass[t, 2] = third
            continue
        s0 = cx * cx + cy * cy + cz * cz
        s1 = bx * bx + by * by + bz * bz
        s2 = ax * ax + ay * ay + az * az
        if d0 < 0.0:
            q0, q1, q2 = 0.25 * dbl, 0.125 * dbl, 0.125 * dbl
        elif d1 < 0.0:
            q0, q1, q2 = 0.125 * dbl, 0.25 * dbl, 0.125 * dbl
        elif d2 < 0.0:
            q0, q1, q2 = 0.125 * dbl, 0.125 * dbl, 0.25 * dbl
        else:
            c0, c1, c2 = d0 / dbl, d1 / dbl, d2 / dbl
            q0 = (s1 * c1 + s2 * c2) / 8.0
            q1 = (s2 * c2 + s0 * c0) / 8.0
            q2 = (s0 * c0 + s1 * c1) / 8.0
        corner_mass[t, 0], corner_mass[t, 1], corner_mass[t, 2] = q0, q1, q2
    return degenerate, first


@njit(cache=True)
def gather_geometry(corners_ptr, corners, corner_slots, indptr, diag_slots, half_cot,
                    corner_mass, live, with_laplacian, L_data, mass):
    """``L_data`` and ``mass`` of :func:`cotan_geometry` from :func:`triangle_terms`,
    one vertex (one row of ``L``) at a time: every entry summed over the vertex's
    triangles in triangle order, as the scatter adds into it, hence bitwise its
    values, with rows apart for the threads.

    Parameters
    ----------
    corners_ptr : (n + 1,) int64 array
    corners : (3 m,) int64 array
        The corners ``3 t + c`` at each vertex, ``t`` increasing
        (:meth:`baselines.laplacian.CotanAssembler.corners`).
    corner_slots, indptr, diag_slots
        The pattern of ``L`` (:class:`baselines.mesh.LaplacianPattern`).
    half_cot, corner_mass : (m, 3) float64 arrays
    live : (m,) bool array
    with_laplacian : bool
    L_data : (nnz,) float64 array, output
    mass : (n,) float64 array, output
    """
    for i in prange(len(mass)):           # vertices apart
        lo, hi = indptr[i], indptr[i + 1]
        if with_laplacian:
            for p in range(lo, hi):
                L_data[p] = 0.0
        diagonal = 0.0
        total = 0.0
        for q in range(corners_ptr[i], corners_ptr[i + 1]):
            t, c = corners[q] // 3, corners[q] % 3
            if not live[t]:
                continue
            if with_laplacian:
                for k in range(3):        # the edges at i: those opposite its other corners
                    if k == c:
                        continue
                    w = half_cot[t, k]
                    slot = corner_slots[t, k, 0]
                    if slot < lo or slot >= hi:
                        slot = corner_slots[t, k, 1]
                    L_data[slot] -= w
                    diagonal += w
            total += corner_mass[t, c]
        if with_laplacian:
            L_data[diag_slots[i]] = diagonal
        mass[i] = total


@njit(cache=True)
def gather_normals(corners_ptr, corners, area_vectors, omega):
    """:func:`vertex_normals` one vertex at a time (the corners of
    :func:`gather_geometry`): the same sums in triangle order, bitwise, vertices apart
    for the threads. Returns the number of vertices whose triangles all have zero
    area (their ``omega`` zero)."""
    bare = 0
    for i in prange(omega.shape[0]):
        ox = oy = oz = weight = 0.0
        for q in range(corners_ptr[i], corners_ptr[i + 1]):
            t = corners[q] // 3
            nx, ny, nz = area_vectors[t, 0], area_vectors[t, 1], area_vectors[t, 2]
            ox += nx
            oy += ny
            oz += nz
            weight += np.sqrt(nx * nx + ny * ny + nz * nz)
        if not weight > 0.0:
            omega[i, 0] = omega[i, 1] = omega[i, 2] = 0.0
            bare += 1
            continue
        omega[i, 0] = ox / weight
        omega[i, 1] = oy / weight
        omega[i, 2] = oz / weight
    return bare


@njit(cache=True, inline="always")
def add_at_corners(faces, t, out, x, y, z, weight, w):
    """Add the vector ``(x, y, z)`` to the rows of ``out`` and ``w`` to ``weight`` at
    the three corners of triangle ``t``: one triangle's part of a weighted vertex
    mean ``sum_t w_t v_t / sum_t w_t`` (:func:`vertex_normals`,
    :func:`baselines.tangential_kernels.vertex_gradients`)."""
    for k in range(3):
        i = faces[t, k]
        out[i, 0] += x
        out[i, 1] += y
        out[i, 2] += z
        weight[i] += w


@njit(cache=True)
def vertex_normals(faces, area_vectors, n, omega):
    """Mass-lumped vertex normals ``omega_k = sum |t| nu_t / sum |t|`` (not normalised).

    Barrett, Garcke, Nuernberg 2008, Section 2 ((B3) of
    :mod:`baselines.bgn`): ``omega_k`` is the area-weighted mean of the unit
    normals ``nu_t`` of the triangles at ``k``; with ``N_t = 2 |t| nu_t``,
    ``omega_k = sum N_t / sum |N_t|``.

    Parameters
    ----------
    faces : (m, 3) int64 array
    area_vectors : (m, 3) float64 array
    n : int
    omega : (n, 3) float64 array, output
        Zero at a vertex whose triangles all have zero area.

    Returns
    -------
    int
        Number of such vertices (never a division by zero here).
    """
    weight = np.zeros(n)
    omega[:] = 0.0
    for t in range(faces.shape[0]):
        nx, ny, nz = area_vectors[t, 0], area_vectors[t, 1], area_vectors[t, 2]
        dbl = np.sqrt(nx * nx + ny * ny + nz * nz)
        add_at_corners(faces, t, omega, nx, ny, nz, weight, dbl)
    bare = 0
    for i in range(n):
        if not weight[i] > 0.0:
            omega[i, 0] = omega[i, 1] = omega[i, 2] = 0.0
            bare += 1
            continue
        omega[i, 0] /= weight[i]
        omega[i, 1] /= weight[i]
        omega[i, 2] /= weight[i]
    return bare


@njit(cache=True)
def row_scaled_system(L_data, indptr, diag_slots, mass, tau, fixed, A_data):
    """Values of ``I + tau diag(1/m) L`` in the pattern of ``L``; rows ``fixed`` = identity.

    The row-scaled form (C3) of ``(M + tau L) X^n = M X^{n-1}`` ((C1) of
    :mod:`baselines.cotan`, (K2) of :mod:`baselines.cmcf`); the Dirichlet
    rows give ``X_i^n = X_i^{n-1}``.

    Parameters
    ----------
    L_data : (nnz,) float64 array
    indptr : (n + 1,) int32 array
    diag_slots : (n,) int64 array
    mass : (n,) float64 array
    tau : float
    fixed : (n,) bool array
    A_data : (nnz,) float64 array, output
        A row whose mass is zero (every triangle at the vertex collapsed)
        is written as an identity row (the vertex stays where it is).

    Returns
    -------
    int
        Number of rows with zero mass (never a division by zero here).
    """
    bare = 0
    for i in prange(len(mass)):           # rows apart: split over threads, bitwise
        lo, hi = indptr[i], indptr[i + 1]
        if not mass[i] > 0.0 and not fixed[i]:
            bare += 1
        if fixed[i] or not mass[i] > 0.0:
            for p in range(lo, hi):
                A_data[p] = 0.0
            A_data[diag_slots[i]] = 1.0
            continue
        s = tau / mass[i]
        for p in range(lo, hi):
            A_data[p] = L_data[p] * s
        A_data[diag_slots[i]] += 1.0
    return bare


@njit(cache=True)
def bgn_system(L_data, indptr, diag_slots, mass, omega, X, tau, fixed, scaled, alpha, A_data,
               b):
    """Values and right-hand side of the BGN system (B4) ``(A + P/tau) X = P X^m / tau``.

    Unknowns by components ``[x_1..x_n, y_1..y_n, z_1..z_n]``; row
    ``c n + i`` of the (3n, 3n) pattern of :func:`baselines.bgn.block_pattern`
    holds, in column order, the couplings ``(d n + i)`` for ``d < c``, the
    entries ``c n + j`` of row ``i`` of ``L``, and the couplings for
    ``d > c``. ``P = diag_k(m_k Omega_k)``, ``Omega_k = alpha I + (1 - alpha) omega_k
    omega_k^T``: BGN's ``omega_k omega_k^T`` for ``alpha = 0``, DeTurck's (D4) of
    :mod:`baselines.deturck` otherwise (there with unit normals).

    Parameters
    ----------
    L_data : (nnz,) float64 array
        Cotangent stiffness ``A`` (one coordinate).
    indptr : (n + 1,) int32 array
        Row pointers of ``L``.
    diag_slots : (n,) int64 array
    mass : (n,) float64 array
        Lumped mass ``m_k``.
    omega : (n, 3) float64 array
        Vertex normals ``omega_k``.
    X : (3, n) float64 array
        ``X^m``.
    tau : float
    fixed : (n,) bool array
        Dirichlet vertices: identity rows, right-hand side ``X^m``.
    scaled : bool
        Multiply row ``(c, k)`` by ``tau / m_k`` (exact: row scaling).
    alpha : float
        The weight of the identity in ``Omega_k``.
    A_data : (3 (nnz + 2 n),) float64 array, output
    b : (3, n) float64 array, output
        Rows of a vertex with zero mass are written like Dirichlet rows.

    Returns
    -------
    int
        Number of non-fixed vertices with zero mass (never a division by zero).
    """
    n = len(mass)
    nnz = indptr[n]
    bare = 0
    for c in range(3):
        for i in prange(n):               # rows apart: split over threads, bitwise
            start = c * (nnz + 2 * n) + indptr[i] + 2 * i
            lo, hi = indptr[i], indptr[i + 1]
            length = hi - lo
            if c == 0 and not fixed[i] and not mass[i] > 0.0:
                bare += 1
            if fixed[i] or not mass[i] > 0.0:
                for p in range(start, start + length + 2):
                    A_data[p] = 0.0
                # the identity row (X^m): for alpha > 0 within an ulp, rounded as the
                # numpy assembly of (D4) rounded it (DeTurck's states bit for bit)
                A_data[start + c + diag_slots[i] - lo] = 1.0 - alpha + alpha
                b[c, i] = X[c, i] - alpha * X[c, i] + alpha * X[c, i]
                continue
            coef = 1.0 if scaled else mass[i] / tau
            s = tau / mass[i] if scaled else 1.0
            wc = omega[i, c]
            # couplings: d < c before the block of L, d > c after it
            q = start
            for d in range(3):
                if d == c:
                    q = start + c + length
                    continue
                v = coef * wc * omega[i, d]
                A_data[q] = v - alpha * v
                q += 1
            base = start + c
            for p in range(lo, hi):
                A_data[base + p - lo] = L_data[p] * s
            v = coef * wc * wc
            diagonal = base + diag_slots[i] - lo
            A_data[diagonal] = A_data[diagonal] + v - alpha * v + alpha * coef
            normal = omega[i, 0] * X[0, i] + omega[i, 1] * X[1, i] + omega[i, 2] * X[2, i]
            v = coef * wc * normal
            b[c, i] = v - alpha * v + alpha * coef * X[c, i]
    return bare


@njit(cache=True)
def dual_mdr_system(L_data, indptr, indices, diag_slots, scale, normal, nu, live, bgn_data,
                    bgn_indptr, indptr6, data):
    """Values of the dual-MDR system (DM5)-(DM6) (:mod:`baselines.dual_mdr`), in the
    pattern of :meth:`baselines.dual_mdr.DualMDRFlow._build_pattern`.

    Row ``c n + k`` (``X``): the values of row ``c n + k`` of BGN's (B4) (``bgn_data``,
    :func:`bgn_system`'s), then ``scale_k L_kj`` (``D A``) at the columns ``3 n + c n + j``.
    Row ``3 n + c n + k`` (``R``): for ``d = 0, 1, 2`` the entries ``j`` of row ``k`` of
    ``L``, ``scale_k L_kj (P_k P_j)_cd`` (``P D A P``, ``P_k = I - nu_k nu_k^T``) plus
    ``normal_k nu_kc nu_kd`` on the diagonal (``N``); a vertex not ``live`` an identity row.

    Parameters
    ----------
    L_data : (nnz,) float64 array
        Cotangent stiffness ``A`` (one coordinate).
    indptr : (n + 1,) int32 array
    indices : (nnz,) int32 array
    diag_slots : (n,) int64 array
        The pattern of ``L``.
    scale : (n,) float64 array
        ``dt / m_k`` (row scaling ``"mass"``) or 1; 0 where not ``live``.
    normal : (n,) float64 array
        The weight of ``nu_k nu_k^T`` in the ``R`` rows: 1 or ``m_k / dt``.
    nu : (n, 3) float64 array
        Unit vertex normals.
    live : (n,) bool array
        Neither fixed nor of zero mass.
    bgn_data : (3 (nnz + 2 n),) float64 array
    bgn_indptr : (3 n + 1,) int32 array
        BGN's matrix (:func:`baselines.bgn.block_pattern`).
    indptr6 : (6 n + 1,) int64 array
        Row pointers of the (6n, 6n) pattern.
    data : (indptr6[-1],) float64 array, output
    """
    n = len(scale)
    for c in range(3):
        for k in range(n):
            lo, hi = indptr[k], indptr[k + 1]
            q = indptr6[c * n + k]
            for s in range(bgn_indptr[c * n + k], bgn_indptr[c * n + k + 1]):
                data[q] = bgn_data[s]
                q += 1
            for p in range(lo, hi):
                data[q] = L_data[p] * scale[k]
                q += 1
            q = indptr6[(3 + c) * n + k]
            a0, a1, a2 = nu[k, 0], nu[k, 1], nu[k, 2]
            ac = nu[k, c]
            for d in range(3):
                ad = nu[k, d]
                for p in range(lo, hi):
                    if not live[k]:
                        data[q] = 1.0 if (p == diag_slots[k] and c == d) else 0.0
                        q += 1
                        continue
                    j = indices[p]
                    bc, bd = nu[j, c], nu[j, d]
                    ab = a0 * nu[j, 0] + a1 * nu[j, 1] + a2 * nu[j, 2]
                    pp = (1.0 if c == d else 0.0) - ac * ad - bc * bd + ab * ac * bd
                    v = scale[k] * L_data[p] * pp
                    if p == diag_slots[k]:
                        v += normal[k] * ac * ad
                    data[q] = v
                    q += 1


@njit(cache=True)
def advected_stiffness(L_data, indptr, indices, mass, Y, n0, G, tension, out):
    """DeTurck's tension (D3) and stiffness ``A + diag(m) D`` of (D4)
    (:mod:`baselines.deturck`), in one pass over the rows of ``L``.

    ``tension_k = -P0_k (L Y)_k / m_k`` (zero where ``m_k <= 0``), ``P0_k = I -
    n0_k n0_k^T``; ``out_p = L_p + m_k (G_p . tension_k)`` at each entry ``p`` of row ``k``.
    The dot products are summed ``(x + z) + y``, as ``numpy.einsum`` sums three terms
    (numpy 2.4): the numbers of the numpy assembly this pass replaced, bit for bit.

    Parameters
    ----------
    L_data : (nnz,) float64 array
    indptr, indices : (n + 1,), (nnz,) int arrays
        The CSR pattern of ``L``.
    mass : (n,) float64 array
    Y, n0 : (n, 3) float64 arrays
        The reference positions and unit vertex normals.
    G : (nnz, 3) float64 array
        :func:`baselines.deturck.reference_gradients`.
    tension : (n, 3) float64 array, output
    out : (nnz,) float64 array, output
    """
    for k in range(len(mass)):
        lo, hi = indptr[k], indptr[k + 1]
        a0 = a1 = a2 = 0.0
        for p in range(lo, hi):
            j = indices[p]
            a0 += L_data[p] * Y[j, 0]
            a1 += L_data[p] * Y[j, 1]
            a2 += L_data[p] * Y[j, 2]
        t0 = t1 = t2 = 0.0
        if mass[k] > 0.0:
            t0, t1, t2 = -(a0 / mass[k]), -(a1 / mass[k]), -(a2 / mass[k])
        normal = n0[k, 0] * t0 + n0[k, 2] * t2 + n0[k, 1] * t1
        t0, t1, t2 = t0 - n0[k, 0] * normal, t1 - n0[k, 1] * normal, t2 - n0[k, 2] * normal
        tension[k, 0], tension[k, 1], tension[k, 2] = t0, t1, t2
        for p in range(lo, hi):
            out[p] = L_data[p] + mass[k] * (G[p, 0] * t0 + G[p, 2] * t2 + G[p, 1] * t1)


@njit(cache=True)
def neighbour_cosines(area_vectors, face_neighbours, cosine, double_areas):
    """How each triangle's normal agrees with those of its edge-neighbours.

    For triangle ``t`` with area vector ``N_t`` (twice its area times its
    unit normal ``nu_t``) the cosine of the angle between ``nu_t`` and the
    area-weighted mean normal of its edge-neighbours ``s``,
    ``nu_t . sum_s N_s / |sum_s N_s|``; negative for a triangle folded
    over its neighbours.

    Parameters
    ----------
    area_vectors : (m, 3) float64 array
    face_neighbours : (m, 3) int64 array
        ``-1`` for no neighbour (boundary edge).
    cosine : (m,) float64 array, output
        NaN for a degenerate triangle or neighbours whose normals cancel.
    double_areas : (m,) float64 array, output
        ``|N_t| = 2 |t|``.
    """
    for t in prange(area_vectors.shape[0]):   # triangles apart
        sx, sy, sz = 0.0, 0.0, 0.0
        for k in range(3):
            s = face_neighbours[t, k]
            if s >= 0:
                sx += area_vectors[s, 0]
                sy += area_vectors[s, 1]
                sz += area_vectors[s, 2]
        nx, ny, nz = area_vectors[t, 0], area_vectors[t, 1], area_vectors[t, 2]
        dbl = np.sqrt(nx * nx + ny * ny + nz * nz)
        double_areas[t] = dbl
        norm = dbl * np.sqrt(sx * sx + sy * sy + sz * sz)
        cosine[t] = (nx * sx + ny * sy + nz * sz) / norm if norm > 0.0 else np.nan
