"""Slow, literal transcriptions for the tests to check the compiled and vectorized code against.

:func:`literal_system`: the paper's equations (2.10)-(2.15), by loops over
vertices and their ordered one-rings with the paper's own indexing, an
independent check of the vectorized assembly. Only the typo in (2.11) is
corrected (chi(V_i^F) in b and c).

:func:`bernoulli`: the Bernoulli function of the drift weights, by ``expm1``,
against which the compiled weights (``ddfv.kernels._bernoulli``,
``baselines.tangential_kernels.bernoulli_weight``: a Taylor series near 0) are checked.

:func:`p1_stiffness`: libigl's cotangent stiffness, against which DDFV's
F-mesh stiffness (``ddfv.tangential_motion.P1Stiffness``, summed in numpy from
half cotangents) is checked.

:func:`boundary_normals`: kll's quadric fit (KL8) in numpy, against which its
compiled pass (``baselines.kll.quadric_normals_kernel``) is checked.
"""

import igl
import numpy as np
import scipy.sparse as sp


def _area(p, q, r):
    return 0.5 * np.linalg.norm(np.cross(q - p, r - p))


def ordered_ring(faces, i):
    """F_{i,p} and T_{i,p} (triangle (F_i, F_{i,p}, F_{i,p+1})), p = 1..m."""
    nxt = {}
    for t, f in enumerate(faces):
        for k in range(3):
            if f[k] == i:
                nxt[f[(k + 1) % 3]] = (f[(k + 2) % 3], t)
    j = next(iter(nxt))
    ring, tris = [], []
    for _ in range(len(nxt)):
        ring.append(j)
        j, t = nxt[j]
        tris.append(t)
    return ring, tris


def literal_system(F, T, faces, tau):
    """Dense matrix of (2.10) and (2.13) on a closed mesh."""
    nf, nt = len(F), len(T)
    A = np.zeros((nf + nt, nf + nt))
    # F-vertices, (2.10)-(2.12)
    for i in range(nf):
        ring, tris = ordered_ring(faces, i)
        m = len(ring)
        qF, qT, chi = np.zeros(m), np.zeros(m), 0.0
        for p in range(m):
            Tp, Tm = T[tris[p]], T[tris[p - 1]]       # T_{i,p}, T_{i,p-1}
            u, v = F[ring[p]] - F[i], Tp - Tm
            S = (F[i] + F[ring[p]] + Tm + Tp) / 4
            gamma = np.linalg.norm(Tm - S) + np.linalg.norm(Tp - S)       # (2.5)
            chi_d = 0.5 * np.linalg.norm(np.cross(u, v))
            d = np.linalg.norm(v)
            cot = u @ v / np.linalg.norm(np.cross(u, v))
            qF[p], qT[p] = gamma * d / chi_d, gamma / d * cot             # (2.12)
            chi += _area(F[i], S, Tp)
        for p in range(m):  # the other half of each diamond: (F_i, T_{i,p}, S_{i,p+1})
            q = (p + 1) % m
            S_next = (F[i] + F[ring[q]] + T[tris[p]] + T[tris[q]]) / 4
            chi += _area(F[i], T[tris[p]], S_next)
        A[i, i] = 1 + tau / (2 * chi) * qF.sum()                          # (2.11)
        for p in range(m):
            A[i, ring[p]] += -tau / (2 * chi) * qF[p]
            A[i, nf + tris[p]] += tau / chi * (qT[p] - qT[(p + 1) % m])
    # T-vertices, (2.13)-(2.15)
    edge_tri = {}
    for t, f in enumerate(faces):
        for k in range(3):
            edge_tri[(f[k], f[(k + 1) % 3])] = t
    for i, f in enumerate(faces):
        qT, qF, chi = np.zeros(3), np.zeros(3), 0.0
        for p in range(3):
            Fp, Fq = F[f[p]], F[f[(p + 1) % 3]]
            Tn = T[edge_tri[(f[(p + 1) % 3], f[p])]]                      # T_{i,p}
            u, v = Fp - Fq, Tn - T[i]    # u = F_{i,p} - F_{i,p+1}: sign of (2.14)
            S = (Fp + Fq + T[i] + Tn) / 4
            gamma = np.linalg.norm(Fp - S) + np.linalg.norm(Fq - S)
            chi_d = 0.5 * np.linalg.norm(np.cross(u, v))
            d = np.linalg.norm(u)
            cot = u @ v / np.linalg.norm(np.cross(u, v))
            qT[p], qF[p] = gamma * d / chi_d, gamma / d * cot             # (2.15)
            chi += _area(T[i], Fp, S) + _area(T[i], S, Fq)
        A[nf + i, nf + i] = 1 + tau / (2 * chi) * qT.sum()                # (2.14)
        for p in range(3):
            Tn = edge_tri[(f[(p + 1) % 3], f[p])]
            A[nf + i, nf + Tn] += -tau / (2 * chi) * qT[p]
            A[nf + i, f[p]] += tau / chi * (qF[p] - qF[p - 1])
    return A


def bernoulli(x):
    """``B(x) = x / (e^x - 1)``, ``B(0) = 1``, elementwise: the Scharfetter-Gummel
    weight of (R4) (``baselines.redistribution``) and (R7) (``ddfv.redistribution``),
    positive, ``-> -x`` for ``x -> -inf``, ``-> 0`` for ``x -> +inf`` (no overflow),
    ``B(-x) = B(x) + x``."""
    x = np.asarray(x, dtype=float)
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        b = x / np.expm1(x)
    return np.where(x == 0.0, 1.0, b)


def p1_stiffness(F, faces):
    """The P1 (cotangent) stiffness ``A = -igl.cotmatrix``: ``A_kj = int grad phi_k .
    grad phi_j``, (n, n) CSR, of the (n, 3) points ``F`` on the (m, 3) ``faces``."""
    return sp.csr_matrix(-igl.cotmatrix(np.asarray(F, dtype=float), faces))


def boundary_normals(vertices, centres, ring, member, rough):
    """kll's boundary normals (KL8) in numpy, as ``baselines.kll.boundary_normals``
    computed them before its compiled pass (``baselines.kll.quadric_normals_kernel``):
    the quadric of each two-ring fitted by ``np.linalg.solve`` of its weighted normal
    equations; (b, 3)."""
    offsets = vertices[ring] - vertices[centres][:, None]                   # (b, k, 3)
    seed = offsets[np.arange(len(ring)), np.argmax(member * np.linalg.norm(
        np.cross(offsets, rough[:, None]), axis=2), axis=1)]
    u1 = np.cross(np.cross(rough, seed), rough)
    u1 /= np.linalg.norm(u1, axis=1, keepdims=True)
    u2 = np.cross(rough, u1)
    squared = (offsets ** 2).sum(axis=2)
    weight = np.divide(1.0, squared, out=np.zeros_like(squared), where=member)
    scale = np.sqrt((member * squared).sum(axis=1) / member.sum(axis=1))
    u, v, w = (np.einsum("bkc,bc->bk", offsets, e) / scale[:, None] for e in (u1, u2, rough))
    # in units of the ring's size, the slopes a, b unchanged
    design = np.stack([u, v, u * u, u * v, v * v], axis=2)
    gram = np.einsum("bki,bk,bkj->bij", design, weight, design)
    moments = np.einsum("bki,bk,bk->bi", design, weight, w)
    a, b = np.linalg.solve(gram, moments[..., None])[:, :2, 0].T
    normal = rough - a[:, None] * u1 - b[:, None] * u2
    return normal / np.linalg.norm(normal, axis=1, keepdims=True)
