"""The classical cotangent scheme for mean curvature flow (Dziuk 1991).

Mean curvature flow ``d/dt X = Delta_{M(t)} X`` discretised with piecewise
linear finite elements, lumped mass and the Laplacian frozen at the previous
time level (G. Dziuk, "An algorithm for evolutionary surfaces", Numer.
Math. 58 (1991) 603-611, the semi-implicit scheme with mass lumping)::

    (M^{n-1} + tau L^{n-1}) X^n = M^{n-1} X^{n-1}                      (C1)

``L`` is the cotangent stiffness matrix (``-igl.cotmatrix``), symmetric and
positive semi-definite (Pinkall and Polthier 1993, the cotangent formula)::

    (L X)_i = 1/2 sum_j (cot alpha_ij + cot beta_ij) (X_i - X_j)      (C2)

(``alpha_ij``, ``beta_ij`` the angles opposite the edge ``ij``) and ``M``
the lumped mass: barycentric, ``M_ii = 1/3 sum_{T ni i} |T|`` (default),
or Voronoi/mixed (Meyer, Desbrun, Schroeder, Barr 2003, Section 3.3;
``igl.MASSMATRIX_TYPE_VORONOI``). Both are rebuilt from the current
surface at every step: true mean curvature flow, with no re-centring,
rescaling or frozen Laplacian.

Open surfaces: boundary vertices are held fixed (Dirichlet, as in the DDFV
scheme): their rows of (C3) are rows of the identity, so that
``X_i^n = X_i^{n-1}``. Interior rows keep the cotangent weights of the
boundary edges (one triangle each).

The solver sees (C1) in the row-scaled form

    (I + tau diag(1 / M^{n-1}) L^{n-1}) X^n = X^{n-1}                 (C3)

(the form of the DDFV system, so that the shared solver's stopping rule
``|r| <= rtol |b|`` and iteration counts mean the same thing), with the
warm start ``2 X^{n-1} - X^{n-2}`` (``X^0`` at the first step).

Assembly (``assembly=``):

``"cached"`` (default)
    :class:`CotanAssembler`: one compiled loop over the triangles
    (:func:`baselines.kernels.cotan_geometry`) writes ``L``, ``M`` and the
    triangle area vectors straight into a CSR pattern built once
    (:func:`baselines.mesh.laplacian_pattern`), and one loop over the rows
    writes (C3). Also used by :mod:`baselines.cmcf` and :mod:`baselines.bgn`.
``"igl"``
    ``igl.cotmatrix`` and ``igl.massmatrix`` at every step (the reference;
    the matrices agree with ``"cached"`` to rounding).

Tangential redistribution (``redistribution="area"``): the area-oriented
tangential velocity ``v_T = grad psi`` of :mod:`baselines.redistribution`
(Mikula, Remesikova, Sarkoci, Sevcovic 2014), ``psi`` from the old state,
enters the matrix as the advection ``grad psi . grad X^n``:
``L`` of (C3) becomes the drift stiffness (R4) (Scharfetter-Gummel weights
``c_ij B(psi_i - psi_j)``), the right-hand side stays ``X^{n-1}``.

The operators are those of :mod:`baselines.laplacian`; the state, the flow
contract and the checks of a state are :class:`baselines.vertex_flow.VertexFlow`'s,
shared by every vertex-based baseline.
"""

import time

import numpy as np

from kept_factor import as_csr

from .tangential_kernels import drifted_system, normal_parts
from .laplacian import cotangent_laplacian, lumped_mass, row_scaled_matrix
from .redistribution import (OMEGA, PECLET, REDISTRIBUTIONS, PotentialSolver, drift_laplacian,
                             redistribution_source, surface_components, tangential_velocity,
                             target_shares)
from .vertex_flow import VertexFlow

ASSEMBLIES = ("cached", "igl")


class CotanFlow(VertexFlow):
    """Cotangent mean curvature flow (C1) of one triangulated surface.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``.
    faces : (m, 3) int array
        Consistently oriented triangles of a manifold surface, closed or
        with boundary; boundary vertices keep their position (Dirichlet).
    tau : float
        Time step.
    mass : {"barycentric", "voronoi"}
        Lumped mass matrix (see :func:`baselines.laplacian.lumped_mass`).
    assembly : {"cached", "igl"}
        See the module docstring.
    redistribution : {None, "area"}
        ``"area"``: add the area-oriented tangential velocity ``v_T = grad
        psi`` of :mod:`baselines.redistribution` (Mikula, Remesikova,
        Sarkoci, Sevcovic 2014) semi-implicitly, as the advection
        ``grad psi^n . grad X^{n+1}`` in the matrix (R3)-(R4).
    omega : float
        Relaxation rate of the area ratios in (R2), ``>= 0``, in 1 / time on a
        surface of the unit sphere's area 4 pi (default
        :data:`baselines.redistribution.OMEGA`): the rate used is
        ``omega 4 pi / A_0``, ``A_0`` the initial area, so that the flow is
        covariant under scaling (time scales as length squared).
    peclet : float
        Largest edge Peclet number ``|psi_j - psi_i|`` the drift (R4) sees
        (R6): the tangential displacement of a step is at most about
        ``peclet tau / h`` (default :data:`baselines.redistribution.PECLET`;
        ``inf``: none).
    target : {"vertex", "triangle"}
        Target covolume areas of (R2): all equal (``"vertex"``, default) or
        those of equal-area triangles (``"triangle"``,
        :func:`baselines.redistribution.target_shares`).

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> flow = CotanFlow(V, F, 0.01)
    >>> A, b = flow.system()
    >>> A.shape, b.shape, round(float(flow.l2_weights.sum()), 4)
    ((4, 4), (3, 4), 13.8564)
    """

    def __init__(self, vertices, faces, tau, *, mass="barycentric", assembly="cached",
                 redistribution=None, omega=OMEGA, peclet=PECLET, target="vertex",
                 threads=1):
        if assembly not in ASSEMBLIES:
            raise ValueError(f"unknown assembly {assembly!r}; choose one of "
                             f"{', '.join(ASSEMBLIES)}")
        if redistribution not in REDISTRIBUTIONS:
            raise ValueError(f"unknown redistribution {redistribution!r}; choose None or "
                             f"'area'")
        if not (np.isfinite(omega) and omega >= 0):
            raise ValueError(f"omega must be a finite number >= 0, got {omega!r}")
        if not peclet > 0:
            raise ValueError(f"peclet must be a positive number (or inf), got {peclet!r}")
        if redistribution and (k := surface_components(faces, len(vertices))) > 1:
            raise ValueError(f"the redistribution (R2) needs a connected surface; this one "
                             f"has {k} components")
        self.target = target
        self._shares = target_shares(faces, len(vertices), target)
        self.assembly = assembly
        self.redistribution = redistribution
        self.omega, self.peclet = float(omega), float(peclet)
        self._area_0 = None
        self._potential_solver = PotentialSolver()
        self.psi = None
        """The potential of the last step's tangential velocity (R2), (n,)."""
        super().__init__(vertices, faces, tau, mass=mass, threads=threads)
        self.timings["potential"] = 0.0

    def _needs_laplacian(self):
        return self.assembly == "cached"

    def laplacian(self, at=None):
        """The stiffness of the step at the state ``at`` (default the current one),
        CSR: ``L`` (C2) of that surface."""
        at = self._X if at is None else at
        if self.assembly == "igl":
            return cotangent_laplacian(at.T, self.faces)
        return self.assembler.laplacian(self._laplacian_data(self.geometry_at(at)))

    def _system_mass(self, at):
        if self.assembly == "igl":
            return lumped_mass(at.T, self.faces, self.mass_type)
        return self.geometry_at(at).mass

    def _laplacian_data(self, geometry):
        return geometry.L_data

    def potential(self, at=None):
        """``psi`` of (R2) at the state ``at`` (default the current one), (n,), with the
        stiffness and mass of the system at ``at``; also stored as :attr:`psi`."""
        at = self._X if at is None else at
        return self._potential(at, self.laplacian(at), self._system_mass(at))

    def _potential(self, at, L, mass):
        clock = time.perf_counter()
        if self._area_0 is None:                                 # the first step's state
            self._area_0 = float(mass.sum())
        rate = self.omega * 4.0 * np.pi / self._area_0           # scale-covariant omega
        f = redistribution_source(L, mass, at, self.fixed, rate, self._shares)
        self.psi = self._potential_solver(L, mass, f)
        self.timings["potential"] += time.perf_counter() - clock
        return self.psi

    def tangential_velocity(self, at=None):
        """``v_T = grad psi`` (R1) at the vertices of the state ``at`` (default the current
        one), (3, n), zero at fixed vertices: the velocity the advection (R3)-(R4) of a
        step carries (a diagnostic; the step itself takes ``psi``)."""
        at = self._X if at is None else at
        alpha, _ = tangential_velocity(at.T, self.faces, self.potential(at))
        alpha[:, self.fixed] = 0.0
        return alpha

    def _system(self, at, base, dt):
        """``A = I + dt diag(1/M*) L*`` (C3) at ``at``, CSR, rows of boundary
        vertices = identity, ``b = B``; with ``redistribution="area"`` ``L*`` is the
        drift stiffness (R4) of the potential ``psi*`` (R2) of ``at`` and ``b = B +
        dt g*`` (R5)."""
        if self.redistribution is None:
            if self.assembly == "igl":
                return row_scaled_matrix(self.laplacian(at), self._system_mass(at), dt,
                                         self.fixed), base
            g = self.geometry_at(at)
            return self.assembler.row_scaled(self._laplacian_data(g), g.mass, dt,
                                             self.fixed, self.threads), base
        L = as_csr(self.laplacian(at))
        mass = self._system_mass(at)
        psi = self._potential(at, L, mass)                                            # (R2)
        if self.assembly == "igl":
            drift, DX = drift_laplacian(L, psi, self.peclet, at)                      # (R4)
            rhs = base + dt * self._normal_drift(at, DX, mass)                        # (R5)
            return row_scaled_matrix(drift, mass, dt, self.fixed), rhs
        return self._drifted_system(at, base, dt, L, mass, psi)

    def _vertex_normals(self, at):
        """(n, 3) the area-weighted vertex normals of ``at``, not normalised."""
        return self.assembler.normals(self.geometry_at(at).area_vectors, self.threads)

    def _drifted_system(self, at, base, dt, L, mass, psi):
        """``(A, b)`` of a redistributing step with the cached assembly: ``A = I + dt
        diag(1/M*) L_psi`` (C3), (R4) and ``b = base + dt g*`` (R5) in one compiled pass
        over the rows of ``L`` (:func:`baselines.tangential_kernels.drifted_system`: the
        numbers of :func:`drift_laplacian`, :meth:`CotanAssembler.row_scaled
        <baselines.laplacian.CotanAssembler.row_scaled>` and :meth:`_normal_drift` bit
        for bit)."""
        A_data, rhs = np.empty(L.nnz), np.empty((3, self.mesh.n_vertices))
        drifted_system(L.indptr, L.indices, L.data, self.assembler.pattern.diag_slots,
                       np.ascontiguousarray(psi, dtype=np.float64), self.peclet,
                       np.asarray(at, dtype=np.float64), self._vertex_normals(at), mass,
                       float(dt), self.fixed, np.asarray(base, dtype=np.float64), A_data, rhs)
        return self.assembler.csr(A_data), rhs

    def _normal_drift(self, at, DX, mass):
        """``g* = N N . (D X*) / m`` (3, n) (R5): the normal part of the drift's
        ``-(L_psi - L) X* / m`` at ``at``, to be added back, from ``DX = (L_psi - L) X*``
        (3, n); zero at fixed vertices."""
        g = np.empty((3, self.mesh.n_vertices))
        normal_parts(self._vertex_normals(at), np.ascontiguousarray(DX), mass, self.fixed, g)
        return g
