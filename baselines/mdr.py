"""Mean curvature flow with the minimal deformation rate (MDR) tangential velocity.

J. Hu, B. Li, "Evolving finite element methods with an artificial tangential
velocity for mean curvature flow and Willmore flow", Numer. Math. 152 (2022)
127-181: the velocity ``v`` of the surface is the one of least deformation
rate ``int |grad_G v|^2`` among the velocities of normal part ``v . nu = -H``
(mean curvature flow). Its Euler-Lagrange equations are a saddle-point system
with a Lagrange multiplier ``kappa``: for all vector ``w`` and scalar ``chi``::

    (grad_G v, grad_G w) + (kappa nu, w) = 0                                  (M1)
    (v . nu, chi) = -(H, chi)                                                 (M2)

(Hu and Li build the flow from (M1)-(M2) with ``H`` and ``nu`` from Huisken's
evolution equations, discretised as in Kovacs, Li, Lubich 2019; we take them
from the position, see below and ``baselines/README.md``.)

Discretisation (derived here; the paper's text beyond its abstract was not
available to us)
--------------------------------------------------------------------------
P1 on the surface ``X*`` where the operators are taken (the integrator's
evaluation state, (I1) of ``mcfbench.running.integrators``), mass-lumped
``(.,.)_h``, ``A`` the cotangent stiffness, ``m_k`` the lumped mass,
``nu_k`` the UNIT area-weighted vertex normal (BGN's (B3) normalised), and
``H`` linearly implicit: the normal part of the cotangent mean curvature
vector of the NEW position with the operators at ``X*``,
``H_k = nu_k . (A X)_k / m_k``. The velocity is the integrator's difference
quotient ``v = (X - B) / dt``. Lumping (M1) with ``w = phi_k e_c`` and (M2)
with ``chi = phi_k``::

    (A v)_k + m_k kappa_k nu_k = 0                                            (M3)
    nu_k . v_k = -nu_k . (A X)_k / m_k                                        (M4)

(M3) fixes ``kappa_k = -nu_k . (A v)_k / m_k`` and says ``P_k (A v)_k = 0``,
``P_k = I - nu_k nu_k^T``: the tangential part of the discrete Laplacian of
``v`` vanishes. Multiplying the tangential equation by ``dt^2 / m_k``, (M4)
by ``dt nu_k`` and adding::

    nu_k nu_k^T X_k + dt (A X)_k / m_k = nu_k nu_k^T B_k + dt P_k (A B)_k / m_k   (M5)

a 3n x 3n system, that of BGN's scheme (B4) row-scaled (``scaling="mass"``)
with unit normals, plus the right-hand side ``dt P (A B) / m``: BGN asks
``P_k (A X)_k = 0`` of the new position, MDR ``P_k (A (X - B))_k = 0`` of the
velocity. The multiplier is eliminated exactly, so the solver never sees the
saddle point: (M5) times ``m_k / dt`` is symmetric positive definite on a
closed surface (like (B4)), and BiCGStab or a sparse LU solve it.
Boundary vertices (open surfaces) are held fixed: identity rows, as in BGN.
"""

import numpy as np

from .bgn import BGNFlow
from .kernels import vertex_normals


def unit_vertex_normals(faces, area_vectors, n, rows=None):
    """The unit area-weighted vertex normals (BGN's (B3) normalised).

    Parameters
    ----------
    faces : (m, 3) int array
    area_vectors : (m, 3) float array
        Twice the area times the unit normal of each triangle.
    n : int
        Number of vertices.
    rows : (b,) int array, optional
        Only the normals of these vertices (default all).

    Returns
    -------
    (n, 3) or (b, 3) float array
        Zero at a vertex whose triangles all vanished.
    """
    omega = np.empty((n, 3))
    vertex_normals(faces, area_vectors, n, omega)
    omega = omega if rows is None else np.take(omega, rows, axis=0)
    length = np.linalg.norm(omega, axis=1)
    return np.divide(omega, length[:, None], out=np.zeros_like(omega),
                     where=length[:, None] > 0)


class UnitNormalBGN(BGNFlow):
    """BGN's system (B4) with the UNIT area-weighted vertex normals: the algebra that
    MDR (M5) and DeTurck (:mod:`baselines.deturck`) share (not a scheme of the
    registry: normalising BGN's normals gives another scheme, ``baselines/README.md``)."""

    def _normals(self, geometry):
        """(n, 3) the unit area-weighted vertex normals (BGN's (B3) normalised); zero at
        a vertex whose triangles all vanished."""
        return unit_vertex_normals(self.faces, geometry.area_vectors, self.mesh.n_vertices)

    def _tangential_laplacian(self, geometry, nu, base):
        """(n, 3) ``P_k (A B)_k``, ``P_k = I - nu_k nu_k^T``: the tangential part of the
        stiffness ``A`` of ``geometry`` applied to ``base`` (3, n), at every vertex (MDR's
        (M5), dual-MDR's (DM6))."""
        AB = self.assembler.laplacian(geometry.L_data) @ np.ascontiguousarray(base).T
        return AB - nu * np.einsum("kc,kc->k", nu, AB)[:, None]


class MDRFlow(UnitNormalBGN):
    """Mean curvature flow with the MDR tangential velocity, (M5), of one surface.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``.
    faces : (m, 3) int array
        Consistently oriented triangles of a manifold surface, closed or with
        boundary; boundary vertices keep their position (Dirichlet).
    tau : float
    scaling : {"mass", "none"}
        Row scaling of the system passed to the solver: (M5) (``"mass"``) or
        (M5) times ``m_k / dt`` (``"none"``, symmetric), as in
        :class:`baselines.bgn.BGNFlow`.

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> A, b = MDRFlow(V, F, 0.01).system()
    >>> A.shape, b.shape
    ((12, 12), (3, 4))
    """

    def _system(self, at, base, dt, scaling):
        """(M5) at ``at``: BGN's system with unit normals, plus ``dt P (A B) / m``."""
        A, b = super()._system(at, base, dt, scaling)
        g = self.geometry_at(at)
        nu = self._normals(g)
        tangential = self._tangential_laplacian(g, nu, base)
        live = ~self.fixed & (g.mass > 0)
        scale = np.divide(dt, g.mass, out=np.zeros_like(g.mass), where=live) \
            if scaling == "mass" else live.astype(float)
        b += (tangential * scale[:, None]).T
        return A, b
