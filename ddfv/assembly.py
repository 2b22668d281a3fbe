"""Assembly of the DDFV system (2.10)-(2.15) over all ``n_F + n_T`` unknowns.

Flux through a dual curve ``gamma`` of a diamond in the direction of the
diagonal ``w``, ``c`` being the other diagonal (derived from (2.3), (2.6),
(2.7); it reproduces (2.8) and (2.13)-(2.15))::

    flux = |gamma| * ( |c|/J * (f along w)  -  (w.c)/(|c| J) * (f along c) )

For the F-covolume curve (w = u, c = v) and the T-covolume curve
(w = v, c = u) this gives, per diamond ``(a, b, t1, t2)``,

    flux_a  = alpha     (f_b - f_a)   - beta     (f_t2 - f_t1) = -flux_b
    flux_t1 = alpha_hat (f_t2 - f_t1) - beta_hat (f_b - f_a)   = -flux_t2

with ``alpha = |gamma^T| |v| / J = q^F / 2`` and
``beta = |gamma^T| (u.v) / (|v| J) = q^T`` (2.12), and
``alpha_hat = |gamma^F| |u| / J = q_hat^T / 2``,
``beta_hat = |gamma^F| (u.v) / (|u| J) = q_hat^F`` (2.15). The fluxes are
odd in ``w`` and even in ``c``, so no orientation convention is needed.

The stiffness matrix ``K`` collects ``-sum flux``: ``K`` has zero row sums
and ``-K X`` approximates the integral of the Laplace-Beltrami operator
over each covolume (2.9). The system of one time step is (2.10), (2.13)::

    (I + tau diag(1 / chi^{n-1}) K^{n-1}) X^n = X^{n-1}

with the rows of boundary F-vertices replaced by ``F^n = F^{n-1}``
(Section 2.2.4) and the missing T-vertex of a boundary diamond substituted
by ``F_a + F_b - T_t1`` in the T-equation (Section 2.2.5).

Assembly: each diamond ``(a, b, t1, t2)`` adds its entries of ``K`` (the
row and column of T-vertex ``t`` is ``n_F + t``)::

    K[a, b] = K[b, a] = -alpha,          K[a, a] += alpha, K[b, b] += alpha
    K[a, t1] -= beta,  K[b, t1] += beta,  K[a, t2] += beta,  K[b, t2] -= beta
    K[t1, a] -= beta_hat,  K[t1, b] += beta_hat,  K[t2, a] += beta_hat,
    K[t2, b] -= beta_hat,  K[t1, t2] = K[t2, t1] = -alpha_hat,
    K[t1, t1] += alpha_hat, K[t2, t2] += alpha_hat

and on a boundary diamond, with ``f_t2 = f_a + f_b - f_t1`` in the
T-equation, ``K[t1, a] -= beta_hat + alpha_hat``, ``K[t1, b] += beta_hat -
alpha_hat``, ``K[t1, t1] += 2 alpha_hat`` (its F-rows are Dirichlet rows).
The entry of F-row ``i`` at T-column ``t`` thus collects the diamonds of
the two edges of triangle ``t`` at ``i``. The CSR pattern and the CSR
position of each of these entries are computed once per mesh
(:class:`Assembler`); one compiled loop over the diamonds adds the values,
each scaled by ``tau / chi`` of its row, into them, the first write into
each entry starting from the identity's value (no pass zeroes the array
first: :func:`ddfv.kernels.system_kernel`).
"""

import copy

import numpy as np
import scipy.sparse as sp


def flux_coefficients(geom):
    """The four flux coefficients of every diamond.

    Parameters
    ----------
    geom : DiamondGeometry
        Or any object with the attributes ``gamma_t, gamma_f, J, len_u,
        len_v, uv`` (arrays or floats).

    Returns
    -------
    alpha, beta, alpha_hat, beta_hat : (n_d,) float arrays
        See the module docstring; (2.12) and (2.15).
    """
    from .kernels import flux_coefficients_kernel

    # the formulas of the compiled assembly, evaluated elementwise by numpy
    return flux_coefficients_kernel.py_func(geom.gamma_t, geom.gamma_f, geom.J,
                                            geom.len_u, geom.len_v, geom.uv)


class Assembler:
    """Sparse assembly of ``K`` and of the system matrix on a fixed mesh.

    The CSR sparsity pattern and, for every diamond, the CSR positions of
    its entries are built once.

    Parameters
    ----------
    mesh : DiamondMesh
    """

    def __init__(self, mesh):
        from . import kernels as k

        n_f, n_t, n = mesh.n_f, mesh.n_t, mesh.n_unknowns
        a, b, t1, t2 = mesh.diamonds.T
        n_d = len(a)
        inner = ~mesh.boundary
        n_i = int(inner.sum())
        # corner (k, t): vertex faces[t, k] of triangle t, stored k-major
        corner_f = mesh.faces.T.ravel()
        corner_t = n_f + np.tile(np.arange(n_t), 3)
        diag = np.arange(n)
        # entry blocks: F-F, F-T corners, T-F corners, T-T, diagonal; every
        # nonzero of the pattern appears once
        rows = np.concatenate([a, b, corner_f, corner_t,
                               n_f + t1[inner], n_f + t2[inner], diag])
        cols = np.concatenate([b, a, corner_t, corner_f,
                               n_f + t2[inner], n_f + t1[inner], diag])
        if len(rows) >= 2**31:
            raise ValueError(f"{len(rows)} nonzeros do not fit 32-bit CSR indices")
        # every entry once: the keys are unique, so any sort gives the CSR order (a
        # quicksort of one int64 key: a few times faster than lexsort of two)
        perm = np.argsort(rows * np.int64(n) + cols)
        slot = np.empty(len(perm), dtype=np.uint32)
        slot[perm] = np.arange(len(perm))          # CSR position of each block entry
        cuts = np.cumsum([0, n_d, n_d, 3 * n_t, 3 * n_t, n_i, n_i, n])
        s_ab, s_ba, s_ft, s_tf, s_t12, s_t21, s_diag = (
            slot[i:j] for i, j in zip(cuts[:-1], cuts[1:]))
        s_ft, s_tf = s_ft.reshape(3, n_t), s_tf.reshape(3, n_t)
        # corners of a diamond: the edge is the half-edge a -> b of t1
        # (faces[t1, k1] = a, faces[t1, k1 + 1] = b) and b -> a of t2
        he_t, he_k = np.divmod(np.arange(3 * n_t), 3)
        he_d = mesh.halfedges.ravel()
        in_t1 = he_t == t1[he_d]
        k1, k2 = np.zeros(n_d, dtype=np.int64), np.zeros(n_d, dtype=np.int64)
        k1[he_d[in_t1]] = he_k[in_t1]
        k2[he_d[~in_t1]] = he_k[~in_t1]
        k1_next, k2_next = (k1 + 1) % 3, (k2 + 1) % 3
        t2_i = t2[inner]
        slots = np.zeros((n_d, k.N_SLOTS), dtype=np.uint32)
        slots[:, k.SLOT_AB], slots[:, k.SLOT_BA] = s_ab, s_ba
        slots[:, k.SLOT_AA], slots[:, k.SLOT_BB] = s_diag[a], s_diag[b]
        slots[:, k.SLOT_A_T1], slots[:, k.SLOT_B_T1] = s_ft[k1, t1], s_ft[k1_next, t1]
        slots[:, k.SLOT_T1_A], slots[:, k.SLOT_T1_B] = s_tf[k1, t1], s_tf[k1_next, t1]
        slots[:, k.SLOT_T1_T1] = s_diag[n_f + t1]
        slots[inner, k.SLOT_A_T2] = s_ft[k2_next[inner], t2_i]
        slots[inner, k.SLOT_B_T2] = s_ft[k2[inner], t2_i]
        slots[inner, k.SLOT_T2_A] = s_tf[k2_next[inner], t2_i]
        slots[inner, k.SLOT_T2_B] = s_tf[k2[inner], t2_i]
        slots[inner, k.SLOT_T1_T2], slots[inner, k.SLOT_T2_T1] = s_t12, s_t21
        slots[inner, k.SLOT_T2_T2] = s_diag[n_f + t2_i]
        self.shape = (n, n)
        self._mesh = mesh
        self._slots = slots
        #: the rows a, b, n_f + t1, n_f + t2 of each diamond (t2 of a boundary one: 0)
        self._rows = np.ascontiguousarray(
            np.stack([a, b, n_f + t1, np.where(inner, n_f + t2, 0)], axis=1), dtype=np.uint32)
        self._diag = np.ascontiguousarray(s_diag)
        self._indices = cols[perm].astype(np.int32)
        self._indptr = np.searchsorted(rows[perm], np.arange(n + 1)).astype(np.int32)
        # a step's matrix is a shallow copy of this one with its values put in: the
        # pattern's arrays shared as the constructor shares them, without its checks of
        # the pattern at every step (33 us a step at 9 000 unknowns)
        self._pattern = sp.csr_matrix((np.zeros(len(self._indices)), self._indices,
                                       self._indptr), shape=self.shape)
        self._inner = np.ascontiguousarray(inner)
        self._has_boundary = mesh.has_boundary
        # Rows of boundary F-vertices are Dirichlet rows (Section 2.2.4).
        self._dirichlet = np.r_[mesh.boundary_vertices, np.zeros(n_t, bool)]
        self._touch = {}                # threads -> (flagged slots, untouched diagonals)

    def _first_touch(self, threads):
        """The slot table with the first write into each entry flagged, and the
        diagonal entries no diamond writes, for the diamond order of ``threads``
        threads (:func:`ddfv.kernels.system_kernel`; kept per thread count).

        Returns
        -------
        slots : (n_d, N_SLOTS) uint32 array
            ``self._slots`` with :data:`ddfv.kernels.FIRST_TOUCH` set on the
            slots of the entries that :func:`ddfv.kernels.system_kernel` adds
            into (not the four it assigns) at their first write in the order
            of :meth:`DiamondMesh.diamond_blocks`: the blocks run in
            parallel write disjoint rows, so the order within each is the
            order of the writes into its entries.
        untouched : uint32 array
            CSR positions of the diagonals of the rows no diamond writes.
        """
        from . import kernels as k

        cache = self._touch
        if threads not in cache:
            order, _ = self._mesh.diamond_blocks(threads)
            boundary_used = np.zeros(k.N_SLOTS, dtype=bool)
            boundary_used[[k.SLOT_AB, k.SLOT_BA, k.SLOT_AA, k.SLOT_BB, k.SLOT_A_T1,
                           k.SLOT_B_T1, k.SLOT_T1_A, k.SLOT_T1_B, k.SLOT_T1_T1]] = True
            accumulated = np.ones(k.N_SLOTS, dtype=bool)
            accumulated[[k.SLOT_AB, k.SLOT_BA, k.SLOT_T1_T2, k.SLOT_T2_T1]] = False
            seen = np.empty(self.nnz, dtype=bool)
            flagged = np.empty_like(self._slots)
            k.first_touch_kernel(self._slots, self._inner, order, boundary_used, accumulated,
                                 seen, flagged)
            cache[threads] = (flagged, self._diag[~seen[self._diag]])
        return cache[threads]

    @property
    def nnz(self):
        return len(self._indices)

    def _matrix(self, geom, scale, shift, threads=1):
        """``diag(scale) K + shift I`` in CSR (:func:`ddfv.kernels.system_kernel`)."""
        from .kernels import system_kernel
        from kept_factor.threads import for_threads

        n_d = self._slots.shape[0]
        factors = []
        for name in ("gamma_t", "gamma_f", "J", "len_u", "len_v", "uv"):
            x = np.asarray(getattr(geom, name), dtype=np.float64)
            if x.shape != (n_d,):
                raise ValueError(f"geometry field {name} has shape {x.shape}, "
                                 f"the mesh needs ({n_d},)")
            factors.append(x)
        data = np.empty(self.nnz)
        order, starts = self._mesh.diamond_blocks(threads)
        slots, untouched = self._first_touch(threads)
        for_threads(system_kernel, threads)(
            self._inner, *factors, slots, self._rows, order, starts, untouched, scale,
            float(shift), data)
        return self.in_pattern(data)

    def in_pattern(self, data):
        """The (n, n) CSR matrix of the values ``data`` (nnz,) in this pattern (its
        arrays shared, no check of the pattern: see ``_pattern``)."""
        A = copy.copy(self._pattern)
        A.data = data
        return A

    def stiffness(self, geom):
        """``K``: minus the sum of fluxes, zero rows at Dirichlet vertices.

        Parameters
        ----------
        geom : DiamondGeometry

        Returns
        -------
        (n, n) scipy.sparse.csr_matrix
            Zero row sums; ``-(K X)_i`` approximates the integral of the
            Laplace-Beltrami operator of ``X`` over covolume ``i`` (2.9).
        """
        return self._matrix(geom, (~self._dirichlet).astype(float), 0.0)

    def system(self, geom, chi, tau, threads=1):
        """System matrix ``I + tau diag(1/chi) K`` of (2.10)-(2.11), (2.13)-(2.14).

        Parameters
        ----------
        geom : DiamondGeometry
            Geometry of time level ``n - 1``.
        chi : (n,) float array
            Covolume areas ``chi^{n-1}``, F-vertices first; ``chi(V_i)``
            of the equation's own covolume scales each row (typo in (2.11)).
        tau : float
            Time step.
        threads : int
            Threads of the fill (:meth:`ddfv.topology.DiamondMesh.diamond_blocks`).

        Returns
        -------
        (n, n) scipy.sparse.csr_matrix
            Dirichlet rows are rows of the identity.
        """
        chi = np.asarray(chi, dtype=np.float64)
        if chi.shape != (self.shape[0],):
            raise ValueError(f"chi must have shape ({self.shape[0]},), got {chi.shape}")
        scale = tau / chi
        if self._has_boundary:
            scale[self._dirichlet] = 0.0
        return self._matrix(geom, scale, 1.0, threads)
