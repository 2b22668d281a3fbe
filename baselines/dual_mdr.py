"""Mean curvature flow by the dual-MDR scheme: MDR's tangential motion with an energy law.

G. Gao, B. Li, R. Tang, "Dual formulations of geometric curvature flows and their
discretizations", arXiv 2604.18288 (2026). MDR's velocity (Hu and Li 2022,
:mod:`baselines.mdr`) has no discrete energy law; a tangential "dual multiplier" ``R``
restores one. The semi-discrete system (the text we read is the authors' abstract and
the summary of Zhang, Andrews and Farrell, arXiv 2605.20371, whose page states that
their system "coincides with the dual-MDR scheme" at the semi-discrete level;
``baselines/README.md``, "dual-mdr", says what we could not read): find ``X``,
scalar ``kappa``, ``p`` and tangential ``R`` with, for all ``y``, ``Q``, ``s``,
``Lambda``::

    (X_t . n, y) = (kappa, y)                                                 (DM1)
    (grad X_t, grad Q) + (p n, Q) = 0                                         (DM2)
    (R . n, s) = 0                                                            (DM3)
    (grad R, grad Lambda) + (kappa n, Lambda) = -(grad X, grad Lambda)        (DM4)

(DM1)'s sign is BGN's (B1), not the summaries' ``-(kappa, y)``: with (DM4) as given,
``kappa n`` is ``Delta X = -H n`` where ``R = 0``, and ``X_t . n = -kappa`` would be the
backward flow (``baselines/README.md``, interpretation 1). Testing (DM4) with
``Lambda = X_t``, (DM2) with ``Q = R``, (DM3) with ``s = p`` and (DM1) with ``y = kappa``:
``d|Gamma|/dt = (grad X, grad X_t) = -||kappa||^2``.

Discretisation (derived here)
-----------------------------
Linearly implicit as MDR's (M5): P1 on the surface ``X*`` where the integrator takes
the operators (``X^n`` for Euler), mass-lumped ``(.,.)_h``, ``A`` the cotangent
stiffness, ``m_k`` the barycentric mass, ``nu_k`` the UNIT area-weighted vertex normal
(BGN's (B3) normalised, as MDR), ``v = (X - B) / dt`` the integrator's difference
quotient and ``X`` the new position in (DM4). The test functions of ``Q`` and
``Lambda`` vanish at the fixed (Dirichlet) vertices, where ``v = 0`` and ``R = 0``.
Lumping, at every other vertex ``k``::

    nu_k . v_k = kappa_k                                                      (DM1h)
    (A v)_k + m_k p_k nu_k = 0                                                (DM2h)
    nu_k . R_k = 0                                                            (DM3h)
    (A R)_k + m_k kappa_k nu_k = -(A X)_k                                     (DM4h)

(DM2h) is MDR's ``P_k (A v)_k = 0`` (``P_k = I - nu_k nu_k^T``); (DM4h) fixes
``kappa_k = -nu_k . (A (X + R))_k / m_k`` and asks ``P_k (A (X + R))_k = 0``. Since
``A X = A B + dt A v``, the two tangential conditions together are
``P_k (A (B + R))_k = 0``: ``R`` depends on ``B`` alone, the tangential field that
makes the discrete Laplacian of ``B + R`` normal. Times ``dt / m_k``, with
``D = diag(dt / m)`` and ``N = diag_k(nu_k nu_k^T)``::

    (D A + N) X + D A R = N B                                                 (DM5)
    (P D A P + N) R = -P D A B                                                (DM6)

(DM5) is BGN's row-scaled (B4) with unit normals (:class:`baselines.mdr.UnitNormalBGN`)
plus ``D A R``; (DM6) the tangential Laplace problem for ``R``, its normal rows
``nu_k . R_k = 0``. One (6n, 6n) system, block upper triangular, unknowns ``(X, R)`` by
components (``x, y, z`` of ``X``, then of ``R``); its diagonal blocks are row scalings
of symmetric positive definite matrices on a closed surface (B4's and ``P A P +
diag(m / dt) N``), so its eigenvalues are real and positive, and BiCGStab solves it
(``baselines/README.md``: far fewer iterations than the symmetric saddle-point form
of (DM1h)-(DM4h), which it equals to the solver's tolerance). (DM5)-(DM6) hold the
multipliers ``kappa``, ``p`` eliminated exactly; ``kappa`` follows from (DM1h).

Energy law (the proof in ``baselines/README.md``): for Euler steps and every
``tau > 0``, ``|Gamma^{n+1}| + tau sum_k m_k kappa_k^2 <= |Gamma^n|``, the sum over
the free vertices, ``m_k`` the mass of ``Gamma^n``.

The state is ``(X, R)`` (6, n), as KLL's carries ``(X, nu, H)``: ``R`` is no initial
data (the step's ``R`` depends on ``B`` only), but the integrator's extrapolation of
it is the solver's initial guess. ``X`` is a view of the first three rows.
"""

import numpy as np
import scipy.sparse as sp

from .kernels import dual_mdr_system
from .laplacian import with_values
from .mdr import UnitNormalBGN

ROWS = 6
"""The state ``(X, R)``: 3 + 3 rows."""


class DualMDRFlow(UnitNormalBGN):
    """Mean curvature flow by the dual-MDR scheme, (DM5)-(DM6), of one surface.

    Parameters
    ----------
    vertices, faces, tau
        As :class:`baselines.mdr.MDRFlow`'s: ``(n, 3)``, ``(m, 3)``, closed or with a
        boundary held fixed (Dirichlet).
    scaling : {"mass", "none"}
        Rows as (DM5)-(DM6) (``"mass"``) or times ``m_k / dt`` (``"none"``: (DM5) is
        then (B4)'s symmetric form plus ``A R``).

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> flow = DualMDRFlow(V, F, 0.01)
    >>> A, b = flow.system()
    >>> A.shape, b.shape, flow.state.shape, flow.X.shape
    ((24, 24), (6, 4), (6, 4), (3, 4))
    """

    def __init__(self, vertices, faces, tau, *, scaling="mass"):
        super().__init__(vertices, faces, tau, scaling=scaling)
        self._adopt(np.vstack([self._X, np.zeros_like(self._X)]))
        self._build_pattern()

    def _build_pattern(self):
        """The CSR pattern of (DM5)-(DM6), built once: row ``c n + k`` the pattern of row
        ``c n + k`` of (B4) (:func:`baselines.bgn.block_pattern`), then ``D A`` at the
        columns ``3 n + c n + j``; row ``3 n + c n + k`` the nine blocks ``P D A P`` in the
        pattern of ``L`` (columns ``3 n + d n + j``). Columns ascend in every row: the
        layout :func:`baselines.kernels.dual_mdr_system` writes."""
        p, n = self.assembler.pattern, self.mesh.n_vertices
        rows_b = np.repeat(np.arange(3 * n), np.diff(self._indptr))
        rows = np.concatenate([rows_b, *(c * n + p.rows for c in range(3)),
                               *((3 + c) * n + p.rows for c in range(3) for d in range(3))])
        cols = np.concatenate([self._indices.astype(np.int64),
                               *((3 + c) * n + p.indices.astype(np.int64) for c in range(3)),
                               *((3 + d) * n + p.indices.astype(np.int64) for c in range(3)
                                 for d in range(3))])
        order = np.lexsort((cols, rows))
        indptr = np.searchsorted(rows[order], np.arange(ROWS * n + 1))
        self._indptr6 = indptr.astype(np.int64)
        self._pattern6 = sp.csr_matrix((np.zeros(len(order)), cols[order].astype(np.int32),
                                        indptr.astype(np.int32)), shape=(ROWS * n, ROWS * n))

    def _adopt(self, U):
        """Make ``U`` (6, n) the state; ``X`` is a view of its first rows."""
        self._U = np.require(U, np.float64, ["C", "W"])
        self._X = self._U[:3]

    @property
    def state(self):
        """(6, n) read-only view of ``(X^n, R^n)``, what :meth:`system` and :meth:`advance`
        work with (``R^n`` the multiplier of the step that reached ``X^n``)."""
        view = self._U.view()
        view.flags.writeable = False
        return view

    @property
    def R(self):
        """(n, 3) read-only view of the dual multiplier of the last step (zero at step 0)."""
        return self.state[3:].T

    def system(self, at=None, base=None, dt=None, *, scaling=None):
        """``(A, b)`` of (DM5)-(DM6) with the operators at the state ``at``.

        Parameters
        ----------
        at, base : (6, n) float arrays, optional
            ``X*`` and ``B`` in their first three rows (their ``R`` rows are not used);
            default the current state.
        dt, scaling : optional
            As :meth:`baselines.bgn.BGNFlow.system`'s.

        Returns
        -------
        A : (6n, 6n) scipy.sparse.csr_matrix
            Block upper triangular, unknowns ``(X, R)`` by components; Dirichlet rows
            identity.
        b : (6, n) float array
            ``B`` and 0 at the Dirichlet vertices.
        """
        return super().system(self._U if at is None else at, base, dt, scaling=scaling)

    def _system(self, at, base, dt, scaling):
        X = self._X if at is self._U else np.ascontiguousarray(at[:3])
        self._assembles_here = at is self._U       # (VertexFlow.system saw at = U)
        B = base[:3]
        bgn, b_bgn = super()._system(X, B, dt, scaling)               # (B4), unit normals
        g, n = self.geometry_at(X), self.mesh.n_vertices
        nu, p = self._normals(g), self.assembler.pattern
        live = ~self.fixed & (g.mass > 0)
        if scaling == "mass":                      # row k times dt / m_k: (DM5)-(DM6)
            scale = np.divide(dt, g.mass, out=np.zeros_like(g.mass), where=live)
            normal = live.astype(float)
        else:
            scale = live.astype(float)
            normal = np.where(live, g.mass / dt, 0.0)
        data = np.empty(self._indptr6[-1])
        dual_mdr_system(g.L_data, p.indptr, p.indices, p.diag_slots, scale, normal, nu, live,
                        bgn.data, self._indptr, self._indptr6, data)
        b = np.empty((ROWS, n))
        b[:3] = b_bgn
        b[3:] = -(self._tangential_laplacian(g, nu, B) * scale[:, None]).T
        return with_values(self._pattern6, data), b

    def advance(self, U):
        """Accept ``U`` (6, n) as the state ``n + 1``."""
        self._adopt(U)
        super().advance(self._X)

    def defects(self):
        """:meth:`baselines.vertex_flow.VertexFlow.defects`, and ``"degenerated"`` for a
        non-finite multiplier ``R``."""
        bad = ~np.isfinite(self._U[3:]).all(axis=0)
        if bad.any():
            return [("degenerated", f"non-finite dual multiplier R at {int(bad.sum())} "
                     f"vertex(es), e.g. vertex {int(np.flatnonzero(bad)[0])}")]
        return super().defects()
