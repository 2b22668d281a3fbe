"""Mean curvature flow reparametrised by the DeTurck trick (Elliott and Fritz 2017).

C. M. Elliott, H. Fritz, "On approximations of the curve shortening flow and
of the mean curvature flow based on the DeTurck trick", IMA J. Numer. Anal.
37 (2017) 543-603: the parametrisation ``u`` of the flowing surface over a
reference surface ``M`` (here the initial mesh) is composed with the
solution of the harmonic map heat flow from ``(M, g(u))`` to ``(M, g_M)``,
run with the time scale ``1 / alpha``. The search tools gave us the
paper's abstract only, not its equations; the equations below are derived
here from that construction (our labels (D1)-(D4); ``baselines/README.md``).

Continuous (derived). With ``tau(u)`` the tension field of the identity
``(M, g(u)) -> (M, g_M)`` and ``M`` embedded in R^3 by ``Y`` (so that
``tau = P_TM Delta_{g(u)} Y``, the tangential part of the Laplacian of the
reference positions on the current surface), the reparametrised flow is::

    d/dt u = Delta_{g(u)} u - (1 / alpha) du(tau(u))                         (D1)

``Delta_{g(u)} u = -H nu`` is normal and ``du(tau)`` tangential, so (D1) is::

    alpha d/dt u + (1 - alpha) (d/dt u . nu) nu = Delta_{g(u)} u - du(tau)   (D2)

the normal velocity is that of mean curvature flow for every ``alpha > 0``
and the tangential one ``-du(tau) / alpha``. The right-hand side equals
``g(u)^{ij} (d_ij u - Gamma(g_M)^k_ij d_k u)``: LINEAR and strictly elliptic
in ``u`` once the metric ``g(u)`` is frozen (the point of the trick). For a
curve over the unit circle by arc length it is ``u_xx / |u_x|^2``, and (D2) is
the curve scheme's ``alpha u_t + (1 - alpha)(u_t . nu) nu = u_xx / |u_x|^2``:
``alpha = 1`` Deckelnick and Dziuk's scheme, ``alpha -> 0`` the BGN-like
equidistribution (the tangential part of ``Delta u - du(tau)`` must vanish),
``alpha -> infinity`` no tangential motion (Dziuk's).

Discretisation (derived). P1 on the surface ``X*`` where the integrator takes
the operators, lumped: ``A`` the cotangent stiffness and ``m_k`` the
barycentric mass of ``X*``, ``nu_k`` its unit area-weighted vertex normals,
``Y`` the positions and ``n0_k`` the unit vertex normals of the reference
(initial) mesh, ``v = (X - B) / dt``::

    tau_k = -P0_k (A Y)_k / m_k,   P0_k = I - n0_k n0_k^T                     (D3)
    Omega_k v_k + (A X)_k / m_k + (D X)_k = 0,
    Omega_k = alpha I + (1 - alpha) nu_k nu_k^T,   (D X)_k = sum_j (tau_k . G_kj) X_j

``G_kj`` the weights of the lumped (area-weighted) gradient at vertex ``k``
on the reference mesh (:func:`reference_gradients`), so that ``(D X)_k`` is
``du(tau)`` at ``k``: the derivative of the map from the reference to the new
surface in the direction ``tau_k``. Times ``dt``, the 3n x 3n system::

    (Omega + dt diag(1/m) (A + diag(m) D)) X = Omega B                          (D4)

linearly implicit: ``A``, ``m``, ``nu`` and ``tau`` at ``X*``, the new
position implicit in both the Laplacian and the advection ``D`` (explicit,
``du(tau)`` would put an explicit diffusion's step limit on the tangential
motion). ``D`` has the pattern of ``A`` and makes (D4) non-symmetric:
BiCGStab or a sparse LU, not CG. ``alpha = 1`` is the cotangent scheme's
row-scaled (C3) plus ``dt D``; ``alpha -> 0`` BGN's (B4) with unit normals
plus ``dt D``. Boundary vertices are fixed (Dirichlet identity rows).
"""

import numpy as np

from .kernels import advected_stiffness
from .mdr import UnitNormalBGN

ALPHA = 0.1
"""Default ``alpha`` (measured in ``baselines/README.md``)."""


def reference_gradients(vertices, faces, pattern):
    """Weights of the lumped gradient of a P1 function at the vertices, in ``pattern``.

    For triangle ``t`` with area vector ``N_t`` (``|N_t| = 2 |t|``) the gradient of
    the hat function of its corner ``j`` is ``N_t x e_j / |N_t|^2`` (``e_j`` the
    edge opposite ``j``, counter-clockwise); the lumped gradient at ``k`` is the
    area-weighted mean over the triangles at ``k`` (that of
    :func:`baselines.tangential_kernels.vertex_gradients` before its projection), so
    ``grad f (x_k) = sum_j G_kj f_j``.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    pattern : baselines.mesh.LaplacianPattern

    Returns
    -------
    (nnz, 3) float array
        ``G_kj`` at the CSR position of ``(k, j)``.
    """
    V = np.asarray(vertices, dtype=float)
    n = len(V)
    P = V[faces]                                                  # (m, 3 corners, 3)
    N = np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0])
    double = np.linalg.norm(N, axis=1)
    edges = P[:, [2, 0, 1]] - P[:, [1, 2, 0]]                     # opposite corner j
    grads = np.cross(N[:, None, :], edges) / double[:, None, None]    # |N| grad phi_j
    keys = pattern.rows.astype(np.int64) * n + pattern.indices
    G = np.zeros((pattern.nnz, 3))
    weight = np.zeros(n)
    for a in range(3):
        np.add.at(weight, faces[:, a], double)
        for b in range(3):
            slots = np.searchsorted(keys, faces[:, a].astype(np.int64) * n + faces[:, b])
            np.add.at(G, slots, grads[:, b])
    return G / weight[pattern.rows][:, None]


class DeTurckFlow(UnitNormalBGN):
    """Mean curvature flow reparametrised by the DeTurck trick, (D4), of one surface.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``, also the reference surface ``M``.
    faces : (m, 3) int array
        Consistently oriented triangles of a manifold surface, closed or with
        boundary; boundary vertices keep their position (Dirichlet).
    tau : float
    alpha : float
        Time scale of the harmonic map heat flow, ``> 0``: the tangential
        velocity is ``-du(tau) / alpha`` (D1). 1: Deckelnick-Dziuk-like;
        towards 0: BGN-like; large: Dziuk's (no tangential motion).
    scaling : {"mass", "none"}
        Rows of (D4) as written (``"mass"``) or times ``m_k / dt``.

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> A, b = DeTurckFlow(V, F, 0.01, alpha=0.5).system()
    >>> A.shape, b.shape
    ((12, 12), (3, 4))
    """

    def __init__(self, vertices, faces, tau, *, alpha=ALPHA, scaling="mass"):
        if not (np.isfinite(alpha) and alpha > 0):
            raise ValueError(f"alpha must be a positive finite number, got {alpha!r}")
        self.alpha = float(alpha)
        super().__init__(vertices, faces, tau, scaling=scaling)
        self._Y = np.ascontiguousarray(self.vertices)            # the reference surface
        self._n0 = self._normals(self.geometry)
        self._G = reference_gradients(self._Y, self.faces, self.assembler.pattern)

    def tension(self, at=None):
        """``tau`` (D3) at the state ``at`` (default the current one), (n, 3): the
        reference-tangent tension of the identity from ``at`` to the reference."""
        return self._advected(self.geometry_at(self._X if at is None else at))[0]

    def _advected(self, geometry):
        """``(tension, A + diag(m) D)``: (D3) and the stiffness of (D4) in the pattern
        of ``A``, at the surface of ``geometry`` (one compiled pass)."""
        p = self.assembler.pattern
        tension, data = np.empty((self.mesh.n_vertices, 3)), np.empty(p.nnz)
        advected_stiffness(geometry.L_data, p.indptr, p.indices, geometry.mass, self._Y,
                           self._n0, self._G, tension, data)
        return tension, data

    def _laplacian_data(self, geometry):
        """``A + diag(m) D`` (D4) in the pattern of ``A``: BGN's system of it with unit
        normals and ``Omega``'s identity part (:attr:`alpha`) is (D4)."""
        return self._advected(geometry)[1]
