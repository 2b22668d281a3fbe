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

This module also holds :class:`VertexFlow`, what every vertex-based
baseline shares: the state, the contract of ``mcfbench.running.flow.SchemeFlow``, the
warm start and the checks of a state (:meth:`VertexFlow.defects`).
"""

import time
from dataclasses import dataclass
from functools import cached_property

import igl
import numpy as np
import scipy.sparse as sp

from .kernels import (cotan_geometry, neighbour_cosines, normal_parts, row_scaled_system,
                      vertex_normals)
from .mesh import edge_mesh, laplacian_pattern
from .redistribution import (OMEGA, PECLET, REDISTRIBUTIONS, PotentialSolver, drift_laplacian,
                             redistribution_source, surface_components, tangential_velocity,
                             target_shares)

MASS_TYPES = {"barycentric": igl.MASSMATRIX_TYPE_BARYCENTRIC,
              "voronoi": igl.MASSMATRIX_TYPE_VORONOI}
ASSEMBLIES = ("cached", "igl")
COLLAPSED = 1e-10
"""A triangle whose area fell below this times the mean area has collapsed."""


def cotangent_laplacian(vertices, faces):
    """Cotangent stiffness matrix ``L = -igl.cotmatrix`` (pos. semi-def.), (C2).

    The libigl reference of :meth:`CotanAssembler.laplacian`.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (n, n) scipy.sparse.csr_matrix
        Symmetric, zero row sums, positive diagonal.
    """
    V, F = _igl_arrays(vertices, faces)
    return (-igl.cotmatrix(V, F)).tocsr()


def lumped_mass(vertices, faces, mass="barycentric"):
    """Diagonal of the lumped mass matrix ``igl.massmatrix``.

    The libigl reference of :meth:`CotanAssembler.geometry`.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    mass : {"barycentric", "voronoi"}
        Barycentric: ``M_ii = 1/3 sum_{T ni i} |T|``; Voronoi: mixed
        Voronoi areas (Meyer et al. 2003). Both sum to the surface area.

    Returns
    -------
    (n,) float array
    """
    V, F = _igl_arrays(vertices, faces)
    return np.asarray(igl.massmatrix(V, F, MASS_TYPES[_mass_type(mass)]).diagonal())


def _igl_arrays(vertices, faces):
    return (np.ascontiguousarray(vertices, dtype=np.float64),
            np.ascontiguousarray(faces, dtype=np.int64))


def _mass_type(mass):
    if mass not in MASS_TYPES:
        raise ValueError(f"unknown mass {mass!r}; choose one of {', '.join(MASS_TYPES)}")
    return mass


@dataclass(frozen=True)
class SurfaceGeometry:
    """What one state of a surface contributes to a step.

    Attributes
    ----------
    L_data : (nnz,) float array or None
        Values of the stiffness ``L`` (C2) in the pattern of the assembler
        (None when not computed).
    mass : (n,) float array
        Lumped mass ``M_ii``.
    area_vectors : (m, 3) float array
        ``(x_1 - x_0) x (x_2 - x_0)`` per triangle (twice the area times
        the unit normal).
    degenerate : int
        Triangles of zero (or non-finite) area, left out of ``L`` and the
        mass by the kernel instead of dividing by zero.
    first_degenerate : int
        The first of them, ``-1`` if none.
    """

    L_data: np.ndarray
    mass: np.ndarray
    area_vectors: np.ndarray
    degenerate: int = 0
    first_degenerate: int = -1


class CotanAssembler:
    """``L`` (C2), ``M`` and the system matrix (C3) on a fixed mesh, compiled.

    The CSR pattern of ``L`` (edges and diagonal) is built once; every call
    runs :func:`baselines.kernels.cotan_geometry` (one loop over the
    triangles) and writes into fresh arrays laid out by that pattern.

    Parameters
    ----------
    mesh : baselines.mesh.EdgeMesh
    mass : {"barycentric", "voronoi"}

    Examples
    --------
    >>> from baselines.mesh import edge_mesh
    >>> V = np.array([[0., 0, 0], [1, 0, 0], [0, 1, 0]])
    >>> F = np.array([[0, 1, 2]])
    >>> asm = CotanAssembler(edge_mesh(F, 3))
    >>> g = asm.geometry(V)
    >>> asm.laplacian(g.L_data).toarray().round(3).tolist()
    [[1.0, -0.5, -0.5], [-0.5, 0.5, 0.0], [-0.5, 0.0, 0.5]]
    >>> g.mass.round(4).tolist()
    [0.1667, 0.1667, 0.1667]
    """

    def __init__(self, mesh, mass="barycentric"):
        self.mesh = mesh
        self.mass_type = _mass_type(mass)
        self.pattern = laplacian_pattern(mesh)

    @property
    def shape(self):
        return self.pattern.shape

    def geometry(self, vertices, with_laplacian=True):
        """Stiffness, lumped mass and area vectors of ``vertices``.

        Parameters
        ----------
        vertices : (n, 3) float array
        with_laplacian : bool
            Compute ``L`` (False: ``L_data`` is None).

        Returns
        -------
        SurfaceGeometry
        """
        p, mesh = self.pattern, self.mesh
        L_data = np.empty(p.nnz) if with_laplacian else np.empty(0)
        mass = np.empty(mesh.n_vertices)
        area_vectors = np.empty((mesh.n_faces, 3))
        degenerate, first = cotan_geometry(
            np.ascontiguousarray(vertices, dtype=np.float64), mesh.faces, p.corner_slots,
            p.diag_slots, self.mass_type == "voronoi", with_laplacian, L_data, mass,
            area_vectors)
        return SurfaceGeometry(L_data if with_laplacian else None, mass, area_vectors,
                               int(degenerate), int(first))

    def csr(self, data):
        """A CSR matrix with the pattern of ``L`` and values ``data``."""
        p = self.pattern
        return sp.csr_matrix((data, p.indices, p.indptr), shape=p.shape, copy=False)

    def laplacian(self, L_data):
        """``L`` (C2) as CSR from :attr:`SurfaceGeometry.L_data`."""
        return self.csr(L_data)

    def row_scaled(self, L_data, mass, tau, fixed):
        """``I + tau diag(1/M) L`` (C3) as CSR; rows ``fixed`` = identity.

        Parameters
        ----------
        L_data : (nnz,) float array
        mass : (n,) float array
        tau : float
        fixed : (n,) bool array
        """
        p = self.pattern
        data = np.empty(p.nnz)
        row_scaled_system(L_data, p.indptr, p.diag_slots, mass, float(tau), fixed, data)
        return self.csr(data)


def row_scaled_matrix(L, mass, dt, fixed):
    """``I + dt diag(1/M) L`` (C3) of any sparsity, CSR, rows ``fixed`` = identity.

    Parameters
    ----------
    L : (n, n) scipy.sparse matrix
        A stiffness (not changed).
    mass : (n,) float array
        Its lumped mass, positive.
    dt : float
    fixed : (n,) bool array

    Returns
    -------
    (n, n) scipy.sparse.csr_matrix
    """
    L = sp.csr_matrix(L, copy=True)
    L.data *= np.repeat(dt / mass, np.diff(L.indptr))
    A = (L + sp.identity(L.shape[0], format="csr")).tocsr()
    return dirichlet_rows(A, fixed) if fixed.any() else A


def dirichlet_rows(A, fixed):
    """Replace the rows ``fixed`` of a CSR matrix by rows of the identity, in place.

    Parameters
    ----------
    A : (n, n) scipy.sparse.csr_matrix
        Must store its diagonal entries.
    fixed : (n,) bool array

    Returns
    -------
    A
    """
    rows = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    slots = np.flatnonzero(fixed[rows])
    A.data[slots] = (A.indices[slots] == rows[slots]).astype(A.dtype)
    return A


class VertexFlow:
    """What every vertex-based baseline shares (the ``mcfbench.running.flow.SchemeFlow`` contract).

    The state is the mesh vertices, stored by components ``X`` (3, n).
    Subclasses implement ``_system(at, base, dt)``, the linear system of
    one step with the operators at a state (:meth:`system`); the harness's
    integrator solves it and hands the result to :meth:`advance`.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0`` (validated by the harness: manifold,
        oriented, no degenerate triangle).
    faces : (m, 3) int array
    tau : float
        Time step, positive and finite.
    mass : {"barycentric", "voronoi"}
        Lumped mass of :class:`CotanAssembler`.

    Attributes
    ----------
    n : int
        Current time level.
    tau : float
    timings : dict
        Seconds spent in ``"assembly"`` (geometry and system); the integrator
        adds ``"solve"``.
    """

    def __init__(self, vertices, faces, tau, *, mass="barycentric"):
        if not (np.isfinite(tau) and tau > 0):
            raise ValueError(f"tau must be a positive finite number, got {tau!r}")
        V = np.asarray(vertices, dtype=np.float64)
        if V.ndim != 2 or V.shape[1] != 3:
            raise ValueError(f"vertices must have shape (n, 3), got {V.shape}")
        self.mesh = edge_mesh(faces, len(V))
        self.assembler = CotanAssembler(self.mesh, mass)
        self.tau = float(tau)
        self.n = 0
        self._X = np.ascontiguousarray(V.T)
        self._assembles_here = True      # where the last system was assembled (geometry)
        self.timings = {"assembly": 0.0, "solve": 0.0}
        # triangles already flipped against their neighbours at step 0
        self._flipped0 = ~(self._normal_agreement() >= 0.0)
        self._area0 = self._triangle_checks[1].mean()

    # -- the contract -------------------------------------------------------
    @property
    def X(self):
        """(3, n) read-only view of ``X^n`` by components."""
        view = self._X.view()
        view.flags.writeable = False
        return view

    @property
    def vertices(self):
        """(n, 3) read-only view of the vertices ``X^n``."""
        return self.X.T

    @property
    def faces(self):
        """(m, 3) the triangles."""
        return self.mesh.faces

    @property
    def fixed(self):
        """(n,) bool: the Dirichlet (boundary) vertices, held at ``X^0``."""
        return self.mesh.boundary_vertices

    @property
    def mass_type(self):
        return self.assembler.mass_type

    @property
    def mass(self):
        """(n,) lumped mass ``M^n_ii`` of the current surface."""
        return self.geometry.mass

    @property
    def l2_weights(self):
        """The lumped mass ``M^n_ii`` (the vertex areas tile the surface once)."""
        return self.geometry.mass

    @property
    def t(self):
        return self.n * self.tau

    def frame(self):
        """``{"vertices": (n, 3)}``: a copy of the current mesh vertices."""
        return {"vertices": self._X.T.copy()}

    @cached_property
    def geometry(self):
        """:class:`SurfaceGeometry` of the current state. Its stiffness ``L_data`` is
        computed only when the last step assembled its system at the state it started
        from (Euler: the next step will again); after a step assembled elsewhere (BDF2,
        at the extrapolated state) the checks and weights of the state need only the
        mass and the area vectors, and :meth:`geometry_at` completes it on demand."""
        return self.assembler.geometry(self._X.T,
                                       self._needs_laplacian() and self._assembles_here)

    def _needs_laplacian(self):
        return True

    @property
    def state(self):
        """(3, n) read-only view of ``X^n``: what :meth:`system` and :meth:`advance`
        work with (the vertex-based schemes keep the caller's numbering)."""
        return self.X

    def geometry_at(self, at):
        """:class:`SurfaceGeometry` of the state ``at`` (3, n) (the cached one of the
        current state when ``at`` is it)."""
        if at is not self._X:
            return self.assembler.geometry(at.T, self._needs_laplacian())
        if self.geometry.L_data is None and self._needs_laplacian():
            self.geometry = self.assembler.geometry(at.T)       # the stiffness too
        return self.geometry

    def system(self, at=None, base=None, dt=None, **options):
        """``(A, b)`` of one step with the operators at the state ``at``.

        The step ``M(X*) (X - B) / dt + L(X*) X = M(X*) g(X*)`` of the harness's
        integrators (``mcfbench.running.integrators``, (I1)) for ``X* = at``,
        ``B = base``; by default the semi-implicit Euler step from the current
        state (``at = base = X^n``, ``dt = tau``).

        Parameters
        ----------
        at, base : (3, n) float arrays, optional
        dt : float, optional
        **options
            Passed to the subclass's ``_system``.

        Returns
        -------
        A : scipy.sparse.csr_matrix
        b : (3, n) float array
        """
        self._assembles_here = at is None
        at = self._X if at is None else at
        base = at if base is None else base
        clock = time.perf_counter()
        A, b = self._system(at, base, self.tau if dt is None else float(dt), **options)
        self.timings["assembly"] += time.perf_counter() - clock
        return A, b

    def _system(self, at, base, dt):
        """``(A, b)`` of :meth:`system` (implemented by subclasses)."""
        raise NotImplementedError

    def advance(self, X):
        """Accept ``X`` (3, n) as the state ``n + 1``."""
        self._X = np.require(X, np.float64, ["C", "W"])
        self.n += 1
        self.__dict__.pop("geometry", None)
        self.__dict__.pop("_triangle_checks", None)

    @cached_property
    def _triangle_checks(self):
        """``(cosine, double_areas)`` of the current state, each (m,)
        (:func:`baselines.kernels.neighbour_cosines`)."""
        m = self.mesh.n_faces
        cosine, double_areas = np.empty(m), np.empty(m)
        neighbour_cosines(self.geometry.area_vectors, self.mesh.face_neighbours, cosine,
                          double_areas)
        return cosine, double_areas

    def _normal_agreement(self):
        return self._triangle_checks[0]

    def defects(self):
        """What is wrong with the current state: ``[(status, description)]``.

        ``"degenerated"``: non-finite coordinates, triangles of zero area
        (which the compiled geometry reports instead of dividing by zero,
        :attr:`SurfaceGeometry.degenerate`), or triangles whose area
        fell below ``1e-10`` x the mean area (a local collapse) or ``1e-12`` x
        the initial mean area (the surface shrinking to a point, as the DDFV
        scheme checks its diamonds). ``"inverted"``: triangles whose
        unit normal has a negative dot product with the area-weighted mean
        normal of their edge-neighbours and did not at step 0
        (:func:`baselines.kernels.neighbour_cosines`).
        """
        if not np.isfinite(self._X).all():
            bad = np.flatnonzero(~np.isfinite(self._X).all(axis=0))
            return [("degenerated", f"non-finite coordinates at {len(bad)} vertex(es), "
                     f"e.g. vertex {int(bad[0])}")]
        g = self.geometry
        if g.degenerate:
            return [("degenerated", f"{g.degenerate} triangle(s) of zero area (no cotangent "
                     f"weights), e.g. triangle {g.first_degenerate}")]
        area = self._triangle_checks[1]
        threshold = max(COLLAPSED * area.mean(), 1e-2 * COLLAPSED * self._area0)
        # the minimum first (one pass; NaN fails it): the indices only for a message
        collapsed = np.flatnonzero(~(area > threshold)) if not area.min() > threshold else ()
        if len(collapsed):
            return [("degenerated", f"{len(collapsed)} triangle(s) collapsed (area below "
                     f"{COLLAPSED:g} x the mean or 1e-12 x the initial mean), e.g. triangle "
                     f"{int(collapsed[0])}")]
        cosine = self._normal_agreement()
        flipped = np.flatnonzero(~(cosine >= 0.0) & ~self._flipped0) \
            if not cosine.min() >= 0.0 else ()
        if len(flipped):
            worst = flipped[np.argmin(cosine[flipped])]
            return [("inverted", f"triangle {int(worst)} flipped against its neighbours "
                     f"(cosine {cosine[worst]:.3g} with their mean normal; "
                     f"{len(flipped)} triangle(s) inverted)")]
        return []


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
        Lumped mass matrix (see :func:`lumped_mass`).
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
                 redistribution=None, omega=OMEGA, peclet=PECLET, target="vertex"):
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
        super().__init__(vertices, faces, tau, mass=mass)
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
                                             self.fixed), base
        L = sp.csr_matrix(self.laplacian(at))
        mass = self._system_mass(at)
        drift, DX = drift_laplacian(L, self._potential(at, L, mass), self.peclet, at)  # (R4)
        rhs = base + dt * self._normal_drift(at, DX, mass)                          # (R5)
        if self.assembly == "igl":
            return row_scaled_matrix(drift, mass, dt, self.fixed), rhs
        return self.assembler.row_scaled(drift.data, mass, dt, self.fixed), rhs

    def _normal_drift(self, at, DX, mass):
        """``g* = N N . (D X*) / m`` (3, n) (R5): the normal part of the drift's
        ``-(L_psi - L) X* / m`` at ``at``, to be added back, from ``DX = (L_psi - L) X*``
        (3, n); zero at fixed vertices."""
        normals = np.empty((self.mesh.n_vertices, 3))
        vertex_normals(self.faces, self.geometry_at(at).area_vectors, self.mesh.n_vertices,
                       normals)
        g = np.empty((3, self.mesh.n_vertices))
        normal_parts(normals, np.ascontiguousarray(DX), mass, self.fixed, g)
        return g
