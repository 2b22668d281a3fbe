"""Compiled (numba) passes of the geometry layer over a mesh's triangles or points.

Imported on first use by the functions they serve (numba is not imported
before, so a command that measures nothing does not pay for it), each kernel
loaded from numba's cache: :func:`quality_pass` (:func:`mcfbench.geometry.metrics.quality`),
:func:`count_folds` (the quality monitor's fold count), :func:`state_pass`
(:class:`mcfbench.geometry.measures.StateMeasures`: what the driver's collapse and
invariant checks read of every state, with the same fold count), :func:`largest_step`
(:func:`mcfbench.geometry.metrics.max_speed`, the steady state's test) and
:func:`sphere_error_sum` (:class:`mcfbench.geometry.exact.SphereL2Error`), tested
through them (the quality monitor's, the speed's and the sphere error's against numpy
evaluations of their formulas).

A triangle ``(x_0, x_1, x_2)`` is read by :func:`_triangle`: its edges ``a = x_1 -
x_0``, ``b = x_2 - x_1``, ``c = x_0 - x_2`` and its normal ``n = (x_1 - x_0) x (x_2 -
x_0) = c x a`` (length twice the area).
"""

import numba
import numpy as np

_OPTIONS = {"cache": True, "nogil": True, "error_model": "numpy"}


@numba.njit(inline="always", **_OPTIONS)
def _triangle(V, F, t):
    """Edges ``a``, ``b``, ``c`` and normal ``n`` of triangle ``t``, twelve floats:
    ``a0, a1, a2, b0, b1, b2, c0, c1, c2, n0, n1, n2``."""
    i0, i1, i2 = F[t, 0], F[t, 1], F[t, 2]
    a0, a1, a2 = V[i1, 0] - V[i0, 0], V[i1, 1] - V[i0, 1], V[i1, 2] - V[i0, 2]
    b0, b1, b2 = V[i2, 0] - V[i1, 0], V[i2, 1] - V[i1, 1], V[i2, 2] - V[i1, 2]
    c0, c1, c2 = V[i0, 0] - V[i2, 0], V[i0, 1] - V[i2, 1], V[i0, 2] - V[i2, 2]
    return (a0, a1, a2, b0, b1, b2, c0, c1, c2,
            c1 * a2 - c2 * a1, c2 * a0 - c0 * a2, c0 * a1 - c1 * a0)


@numba.njit(**_OPTIONS)
def quality_pass(V, F, work):
    """Largest aspect ratio, smallest and largest area;
    ``work[0, t, :2]``: ``|u x v|`` and ``u . v`` of the smallest angle of
    triangle ``t``, ``work[1, t]`` its normal ``n``. NaN
    propagates as in numpy's min/max."""
    m = F.shape[0]
    out = work[0]
    N = work[1]
    asp = -np.inf
    a_min = np.inf
    a_max = -np.inf
    for t in range(m):
        # e_k: corner k -> corner k + 1
        a0, a1, a2, b0, b1, b2, c0, c1, c2, n0, n1, n2 = _triangle(V, F, t)
        la = (a0 * a0 + a2 * a2) + a1 * a1
        lb = (b0 * b0 + b2 * b2) + b1 * b1
        lc = (c0 * c0 + c2 * c2) + c1 * c1
        # the smallest angle is opposite the shortest side (the first one on ties):
        # u = e_{s+2}, v = -e_{s+1}
        if lb < la and lb <= lc:
            u0, u1, u2, v0, v1, v2 = a0, a1, a2, -c0, -c1, -c2
        elif lc < la and lc < lb:
            u0, u1, u2, v0, v1, v2 = b0, b1, b2, -a0, -a1, -a2
        else:
            u0, u1, u2, v0, v1, v2 = c0, c1, c2, -b0, -b1, -b2
        x0 = u1 * v2 - u2 * v1
        x1 = u2 * v0 - u0 * v2
        x2 = u0 * v1 - u1 * v0
        out[t, 0] = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2)
        out[t, 1] = (u0 * v0 + u2 * v2) + u1 * v1
        # normal, area, aspect ratio
        N[t, 0] = n0
        N[t, 1] = n1
        N[t, 2] = n2
        area = 0.5 * np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        sa = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
        sb = np.sqrt(b0 * b0 + b1 * b1 + b2 * b2)
        sc = np.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
        r = sa * sb * sc * (0.5 * (sa + sb + sc)) / (8.0 * (area * area))
        if asp == asp and (r > asp or r != r):
            asp = r
        if a_min == a_min and (area < a_min or area != area):
            a_min = area
        if a_max == a_max and (area > a_max or area != area):
            a_max = area
    return asp, a_min, a_max


@numba.njit(**_OPTIONS)
def count_folds(N, t1, t2, skip, R, S):
    """Number of triangles ``t`` with ``skip[t] == 0`` whose normal ``N[t]`` has
    ``N_t . sum_s N_s < 0`` over its edge-neighbours ``s`` (the pairs ``t1, t2``);
    the sums accumulated like ``np.bincount(t1, N[t2]) + np.bincount(t2, N[t1])``
    into the scratch ``R``, ``S`` (m, 3)."""
    R[:, :] = 0.0
    S[:, :] = 0.0
    for k in range(t1.shape[0]):
        p, q = t1[k], t2[k]
        R[p, 0] += N[q, 0]
        R[p, 1] += N[q, 1]
        R[p, 2] += N[q, 2]
        S[q, 0] += N[p, 0]
        S[q, 1] += N[p, 1]
        S[q, 2] += N[p, 2]
    folded = 0
    for t in range(N.shape[0]):
        d = (N[t, 0] * (R[t, 0] + S[t, 0]) + N[t, 2] * (R[t, 2] + S[t, 2])) \
            + N[t, 1] * (R[t, 1] + S[t, 1])
        if d < 0 and skip[t] == 0:
            folded += 1
    return folded


@numba.njit(**_OPTIONS)
def state_pass(V, F, face_label, labels, neighbours, split, skip, N, area, box, diameter):
    """The measures of a state that the driver's checks read, in one call: one pass
    over the triangles, one over the points, one gathering each triangle's
    edge-neighbours.

    Returns the total area, the smallest tangent of the smallest angles of the
    triangles (the smallest angle of a triangle, opposite its shortest side, is at
    most 60 degrees, so its tangent ``|u x v| / (u . v)`` is increasing in it) and
    the number of triangles ``t`` with ``skip[t] == 0`` whose normal has ``N_t .
    sum_s N_s < 0`` over its edge-neighbours ``s``: the count of
    :func:`count_folds`, bitwise (:func:`_neighbour_sum`). ``neighbours`` (m, w):
    the neighbours of every triangle, those it is the first of a pair ``t1, t2``
    with first (``split[t]`` of them), in the order of the pairs, padded with
    ``m``; ``N`` (m + 1, 3): ``N[t]`` the normal ``n`` of triangle ``t``, ``N[m]``
    zero; ``area[c]``: the sum of the areas of the triangles of component ``c``
    (the total and every component summed in triangle order); ``box[0, c]``,
    ``box[1, c]``: the smallest and largest coordinates of its points (a NaN
    coordinate is skipped: comparisons with NaN are false); ``diameter[c]``: the
    diagonal of that box, rounded as ``np.sqrt(((box[1] - box[0]) ** 2).sum(axis=1))``.
    NaN propagates to the areas and the tangent. ``area``, ``box``, ``diameter``
    and ``N`` are overwritten."""
    m = F.shape[0]
    N[m, :] = 0.0
    total, tangent = _triangles(V, F, face_label, N, area)
    _boxes(V, labels, box, diameter)
    return total, tangent, _folds(N, neighbours, split, skip)


def state_pass_threads(threads, V, F, face_label, labels, neighbours, split, skip, N, area,
                       box, diameter, twice, tangents):
    """:func:`state_pass` on ``threads`` threads (:func:`kept_factor.threads.for_threads`),
    its pass over the triangles in two: each triangle's normal, twice its area and the
    tangent of its smallest angle into ``N``, ``twice`` and ``tangents`` ((m,) scratch),
    triangles apart; then their sums and minimum in triangle order on one thread; the
    fold count triangles apart. The same arithmetic in the same order as
    :func:`state_pass`: bitwise its results."""
    from kept_factor.threads import for_threads

    N[F.shape[0], :] = 0.0
    for_threads(_triangle_terms, threads)(V, F, N, twice, tangents)
    total, tangent = _triangle_sums(face_label, twice, tangents, area)
    _boxes(V, labels, box, diameter)
    return total, tangent, for_threads(_folds, threads)(N, neighbours, split, skip)


# the three passes of state_pass: one compiled function each (in one, the fold count
# ran several times slower); the first in two for threads (state_pass_threads)
@numba.njit(**_OPTIONS)
def _triangles(V, F, face_label, N, area):
    area[:] = 0.0
    total = 0.0
    tangent = np.inf
    for t in range(F.shape[0]):
        twice, tan = _terms(V, F, N, t)
        total += 0.5 * twice
        area[face_label[t]] += 0.5 * twice
        if tangent == tangent and (tan < tangent or tan != tan):
            tangent = tan
    return total, tangent


@numba.njit(**_OPTIONS)
def _triangle_terms(V, F, N, twice, tangents):
    for t in numba.prange(F.shape[0]):    # triangles apart
        twice[t], tangents[t] = _terms(V, F, N, t)


@numba.njit(**_OPTIONS)
def _triangle_sums(face_label, twice, tangents, area):
    area[:] = 0.0
    total = 0.0
    tangent = np.inf
    for t in range(twice.shape[0]):
        total += 0.5 * twice[t]
        area[face_label[t]] += 0.5 * twice[t]
        tan = tangents[t]
        if tangent == tangent and (tan < tangent or tan != tan):
            tangent = tan
    return total, tangent


@numba.njit(inline="always", **_OPTIONS)
def _terms(V, F, N, t):
    """Triangle ``t``'s normal into ``N[t]``; twice its area and the tangent of its
    smallest angle (NaN propagated)."""
    a0, a1, a2, b0, b1, b2, c0, c1, c2, n0, n1, n2 = _triangle(V, F, t)
    N[t, 0] = n0
    N[t, 1] = n1
    N[t, 2] = n2
    twice = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
    la = a0 * a0 + a1 * a1 + a2 * a2
    lb = b0 * b0 + b1 * b1 + b2 * b2
    lc = c0 * c0 + c1 * c1 + c2 * c2
    # the two sides at the smallest angle: the two longest (all three dot
    # products, then one chosen: no branch to mispredict)
    d0 = -(a0 * c0 + a1 * c1 + a2 * c2)     # corner 0: a and -c
    d1 = -(a0 * b0 + a1 * b1 + a2 * b2)     # corner 1: -a and b
    d2 = -(b0 * c0 + b1 * c1 + b2 * c2)     # corner 2: -b and c
    dot = d0 if (lb <= la) & (lb <= lc) else (d1 if lc <= la else d2)
    return twice, twice / dot if dot > 0 else (0.0 if twice == twice else twice)


@numba.njit(**_OPTIONS)
def _boxes(V, labels, box, diameter):
    box[0, :, :] = np.inf
    box[1, :, :] = -np.inf
    for i in range(V.shape[0]):
        c = labels[i]
        for k in range(3):
            x = V[i, k]
            if x < box[0, c, k]:
                box[0, c, k] = x
            if x > box[1, c, k]:
                box[1, c, k] = x
    for c in range(box.shape[1]):
        d0 = box[1, c, 0] - box[0, c, 0]
        d1 = box[1, c, 1] - box[0, c, 1]
        d2 = box[1, c, 2] - box[0, c, 2]
        diameter[c] = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)


@numba.njit(**_OPTIONS)
def _folds(N, neighbours, split, skip):
    folded = 0
    for t in numba.prange(N.shape[0] - 1):    # triangles apart; a count: any order
        r0, r1, r2 = _neighbour_sum(N, neighbours, split, t)
        d = (N[t, 0] * r0 + N[t, 2] * r2) + N[t, 1] * r1
        if d < 0 and skip[t] == 0:
            folded += 1
    return folded


@numba.njit(inline="always", **_OPTIONS)
def _neighbour_sum(N, neighbours, split, t):
    """``R_t + S_t`` of :func:`count_folds`, rounded as there: ``R_t`` the sum of the
    normals of the first ``split[t]`` neighbours, ``S_t`` of the others, each from
    zero in the order of the pairs. With three neighbours (every triangle of a
    closed manifold mesh; padded with the zero ``N[m]`` at a boundary) that is
    ``N_p + (N_q + N_r)`` when ``split[t] == 1``, else ``(N_p + N_q) + N_r``."""
    if neighbours.shape[1] == 3:
        p, q, r = neighbours[t, 0], neighbours[t, 1], neighbours[t, 2]
        if split[t] == 1:
            return (N[p, 0] + (N[q, 0] + N[r, 0]), N[p, 1] + (N[q, 1] + N[r, 1]),
                    N[p, 2] + (N[q, 2] + N[r, 2]))
        return ((N[p, 0] + N[q, 0]) + N[r, 0], (N[p, 1] + N[q, 1]) + N[r, 1],
                (N[p, 2] + N[q, 2]) + N[r, 2])
    r0 = r1 = r2 = s0 = s1 = s2 = 0.0          # more: a non-manifold edge
    for j in range(neighbours.shape[1]):
        s = neighbours[t, j]
        if j < split[t]:
            r0 += N[s, 0]
            r1 += N[s, 1]
            r2 += N[s, 2]
        else:
            s0 += N[s, 0]
            s1 += N[s, 1]
            s2 += N[s, 2]
    return r0 + s0, r1 + s1, r2 + s2


@numba.njit(**_OPTIONS)
def largest_step(P, V):
    """``max_i |V_i - P_i|^2`` of two (n, 3) states in one pass (no temporaries), each
    row's squares summed as ``np.add.reduce(..., axis=1)`` sums three: ``(d_0^2 +
    d_1^2) + d_2^2``. NaN propagates as in numpy's max; ``-inf`` for ``n = 0``."""
    largest = -np.inf
    for i in range(V.shape[0]):
        d0 = V[i, 0] - P[i, 0]
        d1 = V[i, 1] - P[i, 1]
        d2 = V[i, 2] - P[i, 2]
        s = (d0 * d0 + d1 * d1) + d2 * d2
        if largest == largest and (s > largest or s != s):
            largest = s
    return largest


@numba.njit(**_OPTIONS)
def sphere_error_sum(X, c0, c1, c2, r, w):
    """``sum_i w_i (|X_i - c| - r)^2`` in one pass (no temporaries)."""
    total = 0.0
    for i in range(X.shape[1]):
        x0 = X[0, i] - c0
        x1 = X[1, i] - c1
        x2 = X[2, i] - c2
        dist = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2) - r
        total += dist * dist * w[i]
    return total
