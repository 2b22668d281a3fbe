"""The DDFV scheme's flow: its state and the linear system of one time step at a state.

The paper's semi-implicit step (2.1) solves
``(I + tau diag(1/chi^{n-1}) K^{n-1}) X^n = X^{n-1}`` ((2.10), (2.13)) for
the stacked ``X = [F; T]`` (stored by components, shape (3, n_F + n_T)) as
one block system. :meth:`Flow.system` assembles that system with the
operators at any state ``X*`` and the difference quotient from any base
state ``B``; the time integrator that chooses them (the paper's Euler step,
or BDF2), the initial guess and the linear solver (the paper uses
BiCGStab, Section 3) belong to the caller (``mcfbench.running.integrators``),
which then hands the solution to :meth:`Flow.advance`.

Open surfaces: boundary F-vertices keep their position (1.2); see
:mod:`ddfv.assembly`. With ``tangential="eliminate"`` the right-hand side
becomes ``X^{n-1} - tau (h - (h.N) N)`` (3.6), where
``h = -diag(1/chi) K X^{n-1} = (X^{n-1} - A X^{n-1}) / tau`` is the
scheme's own discrete Laplacian of the previous state (zero at Dirichlet
vertices) and ``N`` the vertex normals of
:func:`ddfv.geometry.vertex_normals`.

Numbering: the flow stores its state in its own numbering of the vertices
and triangles (:func:`ddfv.topology.locality_order`), in which neighbours
are close in memory; every public array (``X``, ``F``, ``T``,
``covolumes``, ``barycentric``, ``frame()``, the messages of
``defects()``) is in the caller's numbering. The scheme does not depend
on the numbering; only the order of floating-point sums does.

Invalid states (:meth:`Flow.defects`): non-finite coordinates or collapsed
diamond cells (``"degenerated"``), and a T-vertex whose projection left its
triangle (``"t_escaped"``, Section 2.2.2: "the point T_i^n does not need to
lie in the triangle, only its projection does").
"""

import time
from functools import cached_property

import numpy as np

from kept_factor.threads import check_threads

from .assembly import Assembler
from .geometry import diamond_geometry, t_barycentric, vertex_normals
from .redistribution import (OMEGA, PECLET, TangentialPotential, carry_t_vertices,
                             drift_system, potential_operators, redistribution_source,
                             surface_components, vertex_gradients)
from .t_vertices import initial_t_vertices
from .tangential_motion import KINDS, TangentialMotion, follow_triangles
from .topology import diamond_mesh, locality_order

TANGENTIAL = ("none", "eliminate", "redistribute", *KINDS)
T_MOTIONS = ("scheme", "carried")


def collapsed_cells(measure, threshold, cell, name=str):
    """Describe the cells whose ``measure`` is not above ``threshold``, or None.

    Parameters
    ----------
    measure : (m,) float array
        Areas of the cells (NaN counts as collapsed).
    threshold : float
    cell : str
        Name of a cell in the message, e.g. ``"diamond cell"``.
    name : callable
        ``name(index)``: how the message names a cell (default its index).
    """
    collapsed = np.flatnonzero(~(measure > threshold))
    if len(collapsed) == 0:
        return None
    return f"{len(collapsed)} {cell}(s) collapsed, e.g. {cell} {name(int(collapsed[0]))}"


class Flow:
    """DDFV mean curvature flow of one triangulated surface.

    Parameters
    ----------
    vertices : (n_f, 3) float array
        Initial F-vertices ``F^0``.
    faces : (n_t, 3) int array
        Consistently oriented triangles.
    tau : float
        Time step.
    T0 : (n_t, 3) float array, optional
        Initial T-vertices; by default from ``t_init``.
    t_init : {"paper", "barycenter", "exact"}
        T-vertex initialisation (see :mod:`ddfv.t_vertices`).
    tangential : {"none", "eliminate", "redistribute", "bgn", "mdr"}
        ``"eliminate"`` removes the tangential part of the discrete mean
        curvature vector from the velocity (3.6); ``"redistribute"`` adds
        the area-oriented tangential velocity ``grad psi`` of
        :mod:`ddfv.redistribution` (R1)-(R5) semi-implicitly, as the
        advection ``grad psi^{n-1} . grad X^n`` in the matrix (R6)-(R7);
        ``"bgn"``, ``"mdr"`` keep the normal displacement of each F-vertex
        that the step computed and replace its tangential displacement by
        the one of least Dirichlet energy of the new F-mesh (BGN) or of the
        displacement (MDR) (:mod:`ddfv.tangential_motion`, (TM1)-(TM4)), the
        T-vertices following their triangles.
    omega : float
        Relaxation rate of the redistribution (R2), in 1 / time on a surface
        of the unit sphere's area 4 pi (default :data:`ddfv.redistribution.OMEGA`):
        the rate used is ``omega 4 pi / A_0``, ``A_0`` the initial area, so that
        the flow is covariant under scaling (time scales as length squared).
    peclet : float
        Largest edge Peclet number ``|psi_b - psi_a|`` the drift (R7) sees (R8)
        (default :data:`ddfv.redistribution.PECLET`; ``inf``: none).
    t_motion : {"scheme", "carried"}
        ``"carried"``: after each step every T-vertex is moved tangentially
        back to the barycentric coordinates of its initial projection in its
        triangle, keeping its height above the triangle's plane
        (:func:`ddfv.redistribution.carry_t_vertices`).
    dual_length : {"broken", "chord"}
        Length of the dual curves ``|gamma|``: the paper's broken line (2.5)
        or the chord (see :func:`ddfv.geometry.diamond_geometry`).
    threads : int
        Threads of the compiled passes (geometry, covolumes, matrix fill, T
        monitor; :func:`kept_factor.threads.for_threads`).

    Attributes
    ----------
    F, T : float arrays
        Current state ``F^n``, ``T^n`` (copies, caller's numbering).
    n : int
        Current time level.
    timings : dict
        Seconds spent so far in ``"geometry"`` (including the covolumes and
        the checks of each new state), ``"assembly"``, ``"solve"`` and
        ``"tangential"`` (the motion of ``tangential="bgn"`` or ``"mdr"``); with
        ``tangential="redistribute"`` also ``"potential"``, the part of
        ``"assembly"`` spent on the potential (R3) (its source, stiffness and
        solve).
    """

    def __init__(self, vertices, faces, tau, *, T0=None, t_init="paper",
                 tangential="none", dual_length="broken", threads=1,
                 omega=OMEGA, peclet=PECLET, t_motion="scheme"):
        if not (np.isfinite(tau) and tau > 0):
            raise ValueError(f"tau must be a positive number, got {tau!r}")
        if tangential not in TANGENTIAL:
            raise ValueError(f"unknown tangential {tangential!r}; choose one of "
                             f"{', '.join(TANGENTIAL)}")
        if t_motion not in T_MOTIONS:
            raise ValueError(f"unknown t_motion {t_motion!r}; choose one of "
                             f"{', '.join(T_MOTIONS)}")
        if not (np.isfinite(omega) and omega >= 0):
            raise ValueError(f"omega must be a number >= 0, got {omega!r}")
        if not peclet > 0:
            raise ValueError(f"peclet must be a positive number (or inf), got {peclet!r}")
        check_threads(threads)
        self.threads = threads
        self.omega, self.peclet, self.t_motion = float(omega), float(peclet), t_motion
        self._area_0 = None
        self._faces = diamond_mesh(faces, len(vertices)).faces   # checked, as given
        if tangential == "redistribute" and (k := surface_components(self._faces,
                                                                       len(vertices))) > 1:
            raise ValueError(f"the redistribution (R1)-(R5) needs a connected surface; this "
                             f"one has {k} components")
        n_f, n_t = len(vertices), len(self._faces)
        # the flow's own numbering (module docstring): position j holds the
        # caller's vertex vertex_order[j] and triangle face_order[j]
        vertex_order, self._face_order = locality_order(self._faces, n_f)
        rank = np.empty(n_f, dtype=np.int64)
        rank[vertex_order] = np.arange(n_f)
        self._mesh = diamond_mesh(rank[self._faces[self._face_order]], n_f)
        face_rank = np.empty(n_t, dtype=np.int64)
        face_rank[self._face_order] = np.arange(n_t)
        #: column of the flow's state that holds each caller's point (F, then T)
        self._external = np.concatenate([rank, n_f + face_rank])
        self._vertex_order = vertex_order
        F = np.asarray(vertices, dtype=float)[vertex_order]
        if T0 is None:
            T = initial_t_vertices(F, self._mesh, t_init)
        else:
            T = np.asarray(T0, dtype=float)
            if T.shape != (n_t, 3):
                raise ValueError(f"T0 must have shape {(n_t, 3)}, got {T.shape}")
            T = T[self._face_order]
        self.tau = float(tau)
        self.tangential = tangential
        self.dual_length = dual_length
        self.n = 0
        self._X = np.ascontiguousarray(np.concatenate([F, T]).T)
        self._assembler = Assembler(self._mesh)
        self.timings = {"geometry": 0.0, "assembly": 0.0, "solve": 0.0, "tangential": 0.0}
        self._J0 = self._geometry.J.mean()
        #: barycentric coordinates kept by ``t_motion="carried"`` (own numbering)
        self._lambda0 = self._barycentric[0].copy() if t_motion == "carried" else None
        self._potential = None      # the solver of (R3), kept along the flow
        #: the solver of (TM1)-(TM2), kept along the flow
        self._motion = TangentialMotion(self._mesh.faces, tangential,
                                        fixed=self._mesh.boundary_vertices) \
            if tangential in KINDS else None
        if tangential == "redistribute":
            self.timings["potential"] = 0.0

    @property
    def X(self):
        """(3, n_f + n_t) ``[F^n; T^n]`` by components, caller's numbering (read-only copy)."""
        X = np.take(self._X, self._external, axis=1)
        X.flags.writeable = False
        return X

    @property
    def F(self):
        """(n_f, 3) the F-vertices ``F^n`` (a copy)."""
        return np.take(self._X, self._external[:self._mesh.n_f], axis=1).T

    @property
    def T(self):
        """(n_t, 3) the T-vertices ``T^n`` (a copy)."""
        return np.take(self._X, self._external[self._mesh.n_f:], axis=1).T

    @property
    def t(self):
        return self.n * self.tau

    @cached_property
    def vertices(self):
        """(n_f, 3) the F-vertices (the mesh vertices), read-only: one gather per state
        for all its readers (the driver's checks, the steady-state test, the metric
        observers: three copies of 8 us a step at 3 000 vertices before)."""
        F = self.F
        F.flags.writeable = False
        return F

    @property
    def faces(self):
        """(n_t, 3) the triangles, as given."""
        return self._faces

    @property
    def fixed(self):
        """(n_f,) bool: the Dirichlet (boundary) F-vertices (1.2)."""
        return self._mesh.boundary_vertices[self._external[:self._mesh.n_f]]

    @cached_property
    def _state(self):
        """:meth:`_geometry_at` of the current state, kept until the next step."""
        return self._geometry_at(self._X)

    def _geometry_at(self, X):
        """``(geometry, chi)`` of the state ``X`` (3, n_f + n_t) in one pass (own
        numbering): the :class:`~ddfv.geometry.DiamondGeometry` and the
        (n_f + n_t,) covolume areas ``chi``, F-vertices first."""
        n_f = self._mesh.n_f
        chi = np.empty(self._mesh.n_unknowns)
        geometry = diamond_geometry(self._mesh, X[:, :n_f].T, X[:, n_f:].T,
                                    self.dual_length, self.threads,
                                    vectors=self.tangential != "none",  # normals, gradients
                                    covolumes=chi)
        return geometry, chi

    @property
    def _geometry(self):
        return self._state[0]

    @property
    def _chi(self):
        return self._state[1]

    @property
    def covolumes(self):
        """(n_f + n_t,) covolume areas ``chi^n``, F-vertices first, as ``X``."""
        return np.take(self._chi, self._external)

    @property
    def l2_weights(self):
        """Quadrature weights of the points of ``X`` for the L2 error (3.2):
        ``chi^n / 2`` (the F- and the T-covolumes each tile the surface once)."""
        return 0.5 * self.covolumes

    @cached_property
    def _barycentric(self):
        """(n_t, 3) barycentric coordinates and their minimum (own numbering)."""
        n_f = self._mesh.n_f
        return t_barycentric(self._X[:, :n_f].T, self._X[:, n_f:].T, self._mesh.faces,
                             return_min=True, threads=self.threads)

    @property
    def barycentric(self):
        """(n_t, 3) barycentric coordinates of each T-vertex projected into
        its triangle (the T monitor; Section 3.2)."""
        return self._barycentric[0][self._external[self._mesh.n_f:] - self._mesh.n_f]

    def t_min_barycentric(self):
        """Smallest barycentric coordinate of any T-vertex in its triangle."""
        return self._barycentric[1]

    def frame(self):
        """``{"vertices": (n_f, 3), "extra_points": (n_t, 3)}``: copies of the current
        F-vertices (the mesh vertices) and T-vertices, the harness's frame of a state
        with points besides the mesh vertices."""
        return {"vertices": self.F, "extra_points": self.T}

    @property
    def state(self):
        """(3, n_f + n_t) ``[F^n; T^n]`` in the flow's own numbering (read-only view):
        what :meth:`system` and :meth:`advance` work with."""
        view = self._X.view()
        view.flags.writeable = False
        return view

    def system(self, at=None, base=None, dt=None):
        """The linear system of one step, assembled at the state ``at``.

        The step of (2.1), (2.10)-(2.15) with its operators taken at ``at``
        (``X*``) and the difference quotient taken from ``base`` (``B``)::

            chi(X*) (X - B) / dt + K(X*) X = chi(X*) g(X*)

        i.e. ``(I + dt diag(1/chi*) K*) X = B + dt g*``, ``g = 0`` (the paper),
        ``-(h - (h.N) N)`` with ``h = -diag(1/chi*) K* X*`` (the elimination
        (3.6)); the redistribution weights the F-rows' fluxes by the drift (R6)-(R8)
        and adds ``g*``, the normal part of the drift at ``X*``, back. The paper's step is
        ``at = base = X^{n-1}``, ``dt = tau``; the harness's integrators choose
        them (``mcfbench.running.integrators``). Dirichlet rows: identity, right-hand
        side ``B``.

        Parameters
        ----------
        at, base : (3, n_f + n_t) float arrays, optional
            In the flow's own numbering (:attr:`state`); default the current
            state ``X^{n-1}``.
        dt : float, optional
            Default ``tau``.

        Returns
        -------
        A : (n, n) scipy.sparse.csr_matrix
            Shared by the three components.
        b : (3, n) float array
        """
        at = self._X if at is None else at
        base = at if base is None else base
        dt = self.tau if dt is None else float(dt)
        clock = time.perf_counter()
        geometry, covolumes = self._state if at is self._X else self._geometry_at(at)
        clock = self._tick("geometry", clock)
        A = self._assembler.system(geometry, covolumes, dt, self.threads)
        rhs = base
        if self.tangential == "eliminate":                            # (3.6)
            rhs = self._eliminated(A, at, base, vertex_normals(self._mesh, geometry), dt)
        elif self.tangential == "redistribute":                       # (R6)-(R7)
            N = vertex_normals(self._mesh, geometry)
            psi = self._potential_of(at, A, dt, geometry, covolumes, N)
            A, drifted = drift_system(self._assembler, A, geometry, covolumes, dt, psi,
                                      self.peclet, at)                # drifted: -dt x drift of X*
            rhs = base + np.einsum("ij,ij->j", drifted, N) * N        # + dt g*: normal part back
        self._tick("assembly", clock)
        return A, rhs

    @staticmethod
    def _eliminated(A, at, base, N, dt):
        """(3, n) ``base - dt (h - (h.N) N)``, ``h = (at - A at) / dt`` (3.6): the
        right-hand side of the elimination in one compiled pass
        (:func:`ddfv.tangential_kernels.eliminated_kernel`; numpy's ``h = (at - (A @
        at.T).T) / dt``, ``base - dt * (h - (h * N).sum(axis=0) * N)`` bit for bit, without
        their six (3, n) temporaries: catenoid level 3, the fastest of 500 calls 0.31 ms
        in numpy, 0.20 ms compiled, the product with ``A`` most of it).

        Parameters
        ----------
        A : (n, n) scipy.sparse.csr_matrix
            The step's matrix (the assembler's, int32 indices).
        at, base, N : (3, n) float arrays
        dt : float
        """
        from .tangential_kernels import eliminated_kernel

        out = np.empty((3, A.shape[0]))
        eliminated_kernel(A.indptr, A.indices, A.data, np.asarray(at, dtype=np.float64),
                          np.asarray(base, dtype=np.float64), N, float(dt), out)
        return out

    def advance(self, X):
        """Accept ``X`` (3, n_f + n_t), own numbering, as the state ``n + 1``.

        With ``tangential="bgn"`` or ``"mdr"`` the F-vertices are first moved
        tangentially (TM1)-(TM3) from the current state, the T-vertices with
        their triangles (TM4); with ``t_motion="carried"`` every T-vertex is
        then carried back to its initial barycentric coordinates in its
        triangle.
        """
        X = np.require(X, np.float64, ["C", "W"])   # the compiled passes take writable arrays
        n_f = self._mesh.n_f
        if self.tangential in KINDS:
            X = self._moved_tangentially(X)
        if self.t_motion == "carried":       # a tangential move of the T-vertices
            X = X.copy()
            X[:, n_f:] = carry_t_vertices(X[:, :n_f].T, X[:, n_f:].T, self._mesh.faces,
                                          self._lambda0).T
        self._X = X
        self.n += 1
        for name in ("_state", "_barycentric", "vertices"):
            self.__dict__.pop(name, None)

    def _moved_tangentially(self, X):
        """``X`` (3, n_f + n_t), own numbering, with the F-vertices moved by
        (TM1)-(TM3) from the current state (the old one: its F-mesh's stiffness,
        the scheme's vertex normals (3.6) at the F-vertices) and the T-vertices
        following their triangles (TM4)."""
        clock = time.perf_counter()
        mesh, n_f = self._mesh, self._mesh.n_f
        F_old, F_new, T_new = self._X[:, :n_f].T, X[:, :n_f].T, X[:, n_f:].T
        N = vertex_normals(mesh, self._geometry)[:, :n_f].T
        F = self._motion(F_old, F_new, N)
        lam = t_barycentric(F_new, T_new, mesh.faces, threads=self.threads)
        T = follow_triangles(T_new, F - F_new, mesh.faces, lam)
        self._tick("tangential", clock)
        return np.ascontiguousarray(np.concatenate([F, T]).T)

    def _potential_of(self, at, A, dt, geometry, covolumes, N=None):
        """(n,) ``psi`` of (R3) at the state ``at``; ``A`` the scheme's step matrix at
        ``at`` with step ``dt`` (its discrete Laplacian gives ``h``, as in (3.6)), ``N``
        the vertex normals of ``geometry`` (3, n) when the caller has them."""
        clock = time.perf_counter()
        mesh = self._mesh
        N = vertex_normals(mesh, geometry) if N is None else N
        hV, K = potential_operators(self._assembler, geometry, A, covolumes, dt, at, N)
        if self._area_0 is None:                                 # the first step's state
            self._area_0 = float(covolumes[:mesh.n_f].sum())
        rate = self.omega * 4.0 * np.pi / self._area_0           # scale-covariant omega
        source = redistribution_source(covolumes, hV, mesh.n_f, mesh.boundary_vertices,
                                       rate)                     # (R3)
        if self._potential is None:
            self._potential = TangentialPotential(mesh)
        psi = self._potential(K, source, covolumes)
        self._tick("potential", clock)
        return psi

    def _tangential_velocity(self, at, A, dt, geometry, covolumes):
        """(3, n) ``v_T = grad psi`` (R4)-(R5) of the state ``at``, zero at Dirichlet
        F-vertices: the velocity (R6) carries (diagnostics and tests)."""
        mesh = self._mesh
        psi = self._potential_of(at, A, dt, geometry, covolumes)
        v = vertex_gradients(mesh, geometry, psi, vertex_normals(mesh, geometry))
        v[:, :mesh.n_f][:, mesh.boundary_vertices] = 0.0
        return v

    def _tick(self, phase, since):
        now = time.perf_counter()
        self.timings[phase] += now - since
        return now

    def _edge_name(self, d):
        """``"of edge (a, b)"``, ``a < b``: diamond ``d`` named by its edge in the
        caller's numbering."""
        a, b = np.sort(self._vertex_order[self._mesh.diamonds[d, :2]])
        return f"of edge ({a}, {b})"

    def defects(self):
        """What is wrong with the current state: ``[(status, description)]``.

        ``"degenerated"``: non-finite coordinates, or diamond cells whose
        area ``J`` fell below ``1e-10`` x the mean (a local collapse) or
        ``1e-12`` x the initial mean (the surface shrinking to a point).
        ``"t_escaped"``: the projection of a T-vertex left its triangle (a
        negative barycentric coordinate, Section 2.2.2).
        """
        clock = time.perf_counter()
        try:
            if not np.isfinite(self._X).all():
                return [("degenerated", "non-finite coordinates")]
            J = self._geometry.J
            # J.mean() without its Python wrapper: the same pairwise sum and division
            threshold = max(1e-10 * (np.add.reduce(J) / len(J)), 1e-12 * self._J0)
            if not J.min() > threshold:
                return [("degenerated", collapsed_cells(J, threshold, "diamond cell",
                                                        self._edge_name))]
            if not self.t_min_barycentric() >= 0.0:   # min from the kernel's pass
                smallest = self.barycentric.min(axis=1)
                worst = int(np.argmin(smallest))
                count = int(np.count_nonzero(~(smallest >= 0.0)))
                return [("t_escaped", f"the T-vertex of triangle {worst} left its triangle "
                         f"(barycentric coordinate {smallest[worst]:.3g}; {count} T-vertex(es) "
                         "outside)")]
            return []
        finally:
            self._tick("geometry", clock)
