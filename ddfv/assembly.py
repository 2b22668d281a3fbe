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

Assembly works per half-edge ``h = 3 t + k`` (``faces[t, k] -> faces[t, k+1]``
in triangle ``t``): each half-edge sees its diamond in the frame
``a -> b`` with ``t1 = t``, in which ``u . v`` and hence all four
coefficients are the same for both half-edges of a diamond. The entry of
F-row ``i`` at T-column ``t`` (the corner ``(i, t)``) collects the
diamonds of the two half-edges of ``t`` at ``i``:
``K[i, t] = -beta(out) + beta(in)`` and ``K[t, i] = -beta_hat(out) +
beta_hat(in)``, ``out`` leaving ``i`` and ``in`` entering it. With the
F-F, T-T and diagonal entries, every slot of the sparsity pattern is
written exactly once, so assembly is one permutation of concatenated
blocks.
"""

import numpy as np
import scipy.sparse as sp


def flux_coefficients(geom):
    """The four flux coefficients of every diamond.

    Parameters
    ----------
    geom : DiamondGeometry

    Returns
    -------
    alpha, beta, alpha_hat, beta_hat : (n_d,) float arrays
        See the module docstring; (2.12) and (2.15).
    """
    gt_J = geom.gamma_t / geom.J
    gf_J = geom.gamma_f / geom.J
    return (gt_J * geom.len_v,             # alpha = q^F / 2              (2.12)
            gt_J * geom.uv / geom.len_v,   # beta = |g^T|/d^T cot(omega)  (2.12)
            gf_J * geom.len_u,             # alpha_hat = q_hat^T / 2      (2.15)
            gf_J * geom.uv / geom.len_u)   # beta_hat = q_hat^F           (2.15)


class Assembler:
    """Sparse assembly of ``K`` and of the system matrix on a fixed mesh.

    The CSR sparsity pattern and the permutation from the blocks of
    entries to CSR order are built once.

    Parameters
    ----------
    mesh : DiamondMesh
    """

    def __init__(self, mesh):
        n_f, n_t, n = mesh.n_f, mesh.n_t, mesh.n_unknowns
        a, b, t1, t2 = mesh.diamonds.T
        inner = ~mesh.boundary
        # corner (k, t): vertex faces[t, k]; its out half-edge is k, its in
        # half-edge k - 1 (stored as (3, n_t) rows for contiguous passes)
        corner_f = mesh.faces.T.ravel()
        corner_t = n_f + np.tile(np.arange(n_t), 3)
        diag = np.arange(n)
        # blocks: F-F, F-T corners, T-F corners, T-T, diagonal
        rows = np.concatenate([a, b, corner_f, corner_t,
                               n_f + t1[inner], n_f + t2[inner], diag])
        cols = np.concatenate([b, a, corner_t, corner_f,
                               n_f + t2[inner], n_f + t1[inner], diag])
        perm = np.lexsort((cols, rows))
        self.shape = (n, n)
        self._perm = perm
        self._indices = cols[perm].astype(np.int32)
        self._indptr = np.searchsorted(rows[perm], np.arange(n + 1)).astype(np.int32)
        self._he_out = np.ascontiguousarray(mesh.halfedges.T)
        self._he_in = np.ascontiguousarray(mesh.halfedges[:, [2, 0, 1]].T)
        self._mesh = mesh
        self._inner = inner
        self._has_boundary = mesh.has_boundary
        if self._has_boundary:
            self._bnd_out = mesh.boundary[self._he_out]
            self._bnd_in = mesh.boundary[self._he_in]
        # rows of the F-F, F-T and T-T blocks, for the row scaling
        self._rows_ff = (a, b)
        self._rows_ft = np.ascontiguousarray(mesh.faces.T)
        self._rows_tt = (t1[inner], t2[inner])
        # Rows of boundary F-vertices are Dirichlet rows (Section 2.2.4).
        self._dirichlet = np.r_[mesh.boundary_vertices, np.zeros(n_t, bool)]
        # block boundaries within the entry buffer
        n_d, n_i = len(a), int(inner.sum())
        self._cuts = np.cumsum([0, n_d, n_d, 3 * n_t, 3 * n_t, n_i, n_i, n_f, n_t])
        self._vals = np.empty(self._cuts[-1])

    @property
    def nnz(self):
        return len(self._indices)

    def _entries(self, geom, scale, shift):
        """Values of ``diag(scale) K + shift I`` in CSR order.

        Each block of entries is scaled by the ``scale`` of its rows before
        the one permutation to CSR order.
        """
        mesh = self._mesh
        alpha, beta, alpha_hat, beta_hat = flux_coefficients(geom)
        s_f, s_t = scale[:mesh.n_f], scale[mesh.n_f:]
        ff_ab, ff_ba, ft, tf, tt_12, tt_21, d_f, d_t = (
            self._vals[i:j] for i, j in zip(self._cuts[:-1], self._cuts[1:]))
        ft = ft.reshape(3, -1)
        tf = tf.reshape(3, -1)
        # off-diagonal entries -flux coefficient (module docstring)
        np.multiply(alpha, s_f.take(self._rows_ff[0]), out=ff_ab)
        np.multiply(alpha, s_f.take(self._rows_ff[1]), out=ff_ba)
        np.subtract(beta.take(self._he_in), beta.take(self._he_out), out=ft)
        ft *= s_f.take(self._rows_ft)
        np.subtract(beta_hat.take(self._he_in), beta_hat.take(self._he_out), out=tf)
        ah = alpha_hat.take(self._he_out)
        np.add(ah[0], ah[1], out=d_t)
        d_t += ah[2]
        if self._has_boundary:
            # T_t2 = F_a + F_b - T_t1 on boundary diamonds (Section 2.2.5)
            ah_b = ah * self._bnd_out
            tf -= ah_b + alpha_hat.take(self._he_in) * self._bnd_in
            d_t += ah_b[0] + ah_b[1] + ah_b[2]
            alpha_hat = alpha_hat[self._inner]
        tf *= s_t
        np.multiply(alpha_hat, s_t.take(self._rows_tt[0]), out=tt_12)
        np.multiply(alpha_hat, s_t.take(self._rows_tt[1]), out=tt_21)
        for block in (ff_ab, ff_ba, tt_12, tt_21):
            np.negative(block, out=block)
        # diagonal K_ii = sum of alpha (F rows) or alpha_hat (T rows): zero row sums
        a, b = self._rows_ff
        np.add(np.bincount(a, alpha, minlength=mesh.n_f),
               np.bincount(b, alpha, minlength=mesh.n_f), out=d_f)
        d_f *= s_f
        d_t *= s_t
        if shift:
            d_f += shift
            d_t += shift
        return self._vals.take(self._perm)

    def _csr(self, data):
        return sp.csr_matrix((data, self._indices, self._indptr),
                             shape=self.shape)

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
        data = self._entries(geom, (~self._dirichlet).astype(float), 0.0)
        return self._csr(data)

    def system(self, geom, chi, tau):
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

        Returns
        -------
        (n, n) scipy.sparse.csr_matrix
            Dirichlet rows are rows of the identity.
        """
        scale = tau / chi
        if self._has_boundary:
            scale[self._dirichlet] = 0.0
        return self._csr(self._entries(geom, scale, 1.0))
