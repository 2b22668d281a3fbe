"""The classical cotangent scheme for mean curvature flow (baseline).

Mean curvature flow ``d/dt X = Delta_{M(t)} X`` discretised with piecewise
linear finite elements, lumped mass and the Laplacian frozen at the previous
time level (Dziuk 1991)::

    (M^{n-1} + tau L^{n-1}) X^n = M^{n-1} X^{n-1}                      (C1)

``L = -igl.cotmatrix(V, F)`` is the cotangent stiffness matrix, symmetric
and positive semi-definite::

    (L X)_i = 1/2 sum_j (cot alpha_ij + cot beta_ij) (X_i - X_j)      (C2)

(``alpha_ij``, ``beta_ij`` the angles opposite the edge ``ij``) and ``M``
the lumped mass matrix of ``igl.massmatrix``: barycentric,
``M_ii = 1/3 sum_{T ni i} |T|`` (default), or Voronoi (Meyer et al. 2003).
Both are rebuilt from the current surface at every step: this is true mean
curvature flow, with no re-centring, rescaling or frozen Laplacian.

Open surfaces: boundary vertices are held fixed (Dirichlet boundary (1.2),
as in the DDFV scheme): their rows of (C3) are replaced by rows of the
identity, so that ``X_i^n = X_i^{n-1}``. Interior rows keep the cotangent
weights of the boundary edges (one triangle each).

To share the solver, stopping rule, warm start and iteration count with the
DDFV scheme (:mod:`ddfv.stepping`), (C1) is solved in the row-scaled form

    (I + tau diag(1 / M^{n-1}) L^{n-1}) X^n = X^{n-1}                 (C3)

by :func:`ddfv.solver.bicgstab` on the (3, n) block, stopping at
``|r| <= rtol |X^{n-1}|`` and starting from ``2 X^{n-1} - X^{n-2}``
(``X^0`` at the first step).

Assembly (``assembly=``):

``"cached"`` (default)
    libigl's per-triangle cotangent weights (``igl.cotmatrix_entries``)
    and double areas (``igl.doublearea``) scattered into a CSR pattern
    built once, like :class:`ddfv.assembly.Assembler`; the matrices equal
    those of ``"igl"`` up to rounding (``tests/test_cotan.py``).
``"igl"``
    ``igl.cotmatrix`` and ``igl.massmatrix`` called at every step.
"""

import time
from dataclasses import dataclass
from functools import cached_property

import igl
import numpy as np
import scipy.sparse as sp

from ddfv.errors import SphereL2Error
from ddfv.solver import bicgstab
from ddfv.sphere import T_FINAL, SphereRun, level_time_step, time_steps
from ddfv.stepping import (DEFAULT_RTOL, FlowBreakdown, collapsed_cells, run_steps,
                           validate_vertices)
from ddfv.surfaces import icosphere
from ddfv.topology import diamond_mesh

MASS_TYPES = {"barycentric": igl.MASSMATRIX_TYPE_BARYCENTRIC,
              "voronoi": igl.MASSMATRIX_TYPE_VORONOI}
ASSEMBLIES = ("cached", "igl")
_COLLAPSED = 1e-10  # a triangle whose area fell below this x the mean area


def cotangent_laplacian(vertices, faces):
    """Cotangent stiffness matrix ``L = -igl.cotmatrix`` (pos. semi-def.), (C2).

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array

    Returns
    -------
    (n, n) scipy.sparse.csr_matrix
        Symmetric, zero row sums, positive diagonal.

    Examples
    --------
    >>> V, F = icosphere(1)
    >>> L = cotangent_laplacian(V, F)
    >>> bool(abs(L.sum(axis=1)).max() < 1e-12), bool(L.diagonal().min() > 0)
    (True, True)
    """
    V, F = _igl_arrays(vertices, faces)
    return (-igl.cotmatrix(V, F)).tocsr()


def lumped_mass(vertices, faces, mass="barycentric"):
    """Diagonal of the lumped mass matrix ``igl.massmatrix``.

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


class Assembler:
    """``L`` (C2), ``M`` and the system matrix (C3) on a fixed mesh.

    The CSR pattern of ``L`` (edges and diagonal) and the permutation from
    the blocks of entries to CSR order are built once; each call scatters
    libigl's per-triangle weights into it.

    Parameters
    ----------
    mesh : ddfv.topology.DiamondMesh
        Its diamonds are the edges ``(a, b)``; ``halfedges[t, k]`` is the
        edge ``faces[t, k] -> faces[t, k + 1]``.
    fixed : (n,) bool array, optional
        Dirichlet vertices: their rows of the system matrix (C3) are rows of
        the identity. Default: the boundary vertices of ``mesh``.
    """

    def __init__(self, mesh, fixed=None):
        n = mesh.n_f
        a, b = mesh.diamonds[:, 0], mesh.diamonds[:, 1]
        diag = np.arange(n)
        rows = np.concatenate([a, b, diag])
        cols = np.concatenate([b, a, diag])
        perm = np.lexsort((cols, rows))
        inverse = np.empty_like(perm)
        inverse[perm] = np.arange(len(perm))
        self.shape = (n, n)
        self._a, self._b = a, b
        self._faces = np.ascontiguousarray(mesh.faces, dtype=np.int64)
        # igl.cotmatrix_entries column k belongs to the edge opposite corner
        # k, i.e. the half-edge faces[t, k+1] -> faces[t, k+2]
        self._opposite = np.ascontiguousarray(mesh.halfedges[:, [1, 2, 0]]).ravel()
        self._corners = self._faces.ravel()
        self._n_edges = len(a)
        self._perm = perm
        self._rows = rows[perm]
        self._indices = cols[perm].astype(np.int32)
        self._indptr = np.searchsorted(self._rows, np.arange(n + 1)).astype(np.int32)
        self._diag = inverse[-n:]
        fixed = mesh.boundary_vertices if fixed is None else np.asarray(fixed, dtype=bool)
        # CSR slots of the Dirichlet rows and their identity values
        self._fixed_slots = np.flatnonzero(fixed[self._rows])
        self._fixed_values = (self._indices[self._fixed_slots]
                              == self._rows[self._fixed_slots]).astype(float)

    def edge_weights(self, vertices):
        """``w_ab = 1/2 (cot alpha_ab + cot beta_ab)`` for every edge, (C2)."""
        C = igl.cotmatrix_entries(vertices, self._faces)
        return np.bincount(self._opposite, C.ravel(), minlength=self._n_edges)

    def _data(self, vertices):
        w = self.edge_weights(vertices)
        n = self.shape[0]
        diag = np.bincount(self._a, w, minlength=n) + np.bincount(self._b, w, minlength=n)
        return np.concatenate([-w, -w, diag]).take(self._perm)

    def laplacian(self, vertices):
        """``L = -igl.cotmatrix(vertices, faces)`` as CSR, (C2)."""
        return sp.csr_matrix((self._data(vertices), self._indices, self._indptr),
                             shape=self.shape)

    def barycentric_mass(self, double_areas):
        """``M_ii = 1/3 sum_{T ni i} |T|`` from ``igl.doublearea``."""
        return np.bincount(self._corners, np.repeat(double_areas / 6.0, 3),
                           minlength=self.shape[0])

    def system(self, vertices, mass, tau):
        """``I + tau diag(1/M) L`` of (C3) as CSR, Dirichlet rows = identity.

        Parameters
        ----------
        vertices : (n, 3) float array
            Surface of time level ``n - 1``.
        mass : (n,) float array
            ``M^{n-1}``.
        tau : float
        """
        data = self._data(vertices) * (tau / mass).take(self._rows)
        data[self._diag] += 1.0
        data[self._fixed_slots] = self._fixed_values
        return sp.csr_matrix((data, self._indices, self._indptr), shape=self.shape)


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


class Flow:
    """Cotangent mean curvature flow of one triangulated surface.

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
    rtol : float
        BiCGStab relative tolerance ``|r| <= rtol |X^{n-1}|``.
    maxiter : int
        BiCGStab iteration limit per step.
    assembly : {"cached", "igl"}
        See the module docstring.

    Attributes
    ----------
    V : (n, 3) float array
        Current state ``X^n``.
    n : int
        Current time level.
    fixed : (n,) bool array
        The boundary (Dirichlet) vertices.
    """

    def __init__(self, vertices, faces, tau, *, mass="barycentric",
                 rtol=DEFAULT_RTOL, maxiter=1000, assembly="cached"):
        if not (np.isfinite(tau) and tau > 0):
            raise ValueError(f"tau must be a positive number, got {tau!r}")
        if not (0 < rtol < 1):
            raise ValueError(f"rtol must lie in (0, 1), got {rtol!r}")
        if int(maxiter) != maxiter or maxiter < 1:
            raise ValueError(f"maxiter must be a whole number >= 1, got {maxiter!r}")
        if assembly not in ASSEMBLIES:
            raise ValueError(f"unknown assembly {assembly!r}; choose one of "
                             f"{', '.join(ASSEMBLIES)}")
        self.mass_type = _mass_type(mass)
        self.mesh = diamond_mesh(faces, len(vertices))
        V = validate_vertices(vertices, self.mesh.faces)
        self.fixed = self.mesh.boundary_vertices
        self.tau, self.rtol, self.maxiter = float(tau), float(rtol), int(maxiter)
        self.assembly = assembly
        self.faces = np.ascontiguousarray(self.mesh.faces, dtype=np.int64)
        self._assembler = Assembler(self.mesh) if assembly == "cached" else None
        self.n = 0
        self._X = np.ascontiguousarray(V.T)
        self._X_prev = self._X
        try:
            self._check_geometry()
        except FlowBreakdown as err:
            raise ValueError(f"initial surface is degenerate: {err}") from None

    @property
    def V(self):
        """(n, 3) view of the vertices ``X^n``."""
        return self._X.T

    @property
    def X(self):
        """(3, n) read-only view of ``X^n`` by components."""
        view = self._X.view()
        view.flags.writeable = False
        return view

    @property
    def l2_weights(self):
        """Quadrature weights of the L2 error over the vertices: the lumped
        mass ``M^n_ii`` (the vertex areas tile the surface once)."""
        return self.mass

    @property
    def t(self):
        return self.n * self.tau

    @cached_property
    def _vertices(self):
        return np.ascontiguousarray(self._X.T)

    @cached_property
    def double_areas(self):
        """(m,) twice the triangle areas of ``X^n`` (``igl.doublearea``)."""
        return igl.doublearea(self._vertices, self.faces).ravel()

    @cached_property
    def mass(self):
        """(n,) lumped mass ``M^n_ii`` of the current surface."""
        if self._assembler is not None and self.mass_type == "barycentric":
            return self._assembler.barycentric_mass(self.double_areas)
        return lumped_mass(self._vertices, self.faces, self.mass_type)

    def laplacian(self):
        """``L^n`` (C2) of the current surface, CSR."""
        if self._assembler is not None:
            return self._assembler.laplacian(self._vertices)
        return cotangent_laplacian(self._vertices, self.faces)

    def system(self):
        """``I + tau diag(1/M^n) L^n`` (C3), CSR; rows of boundary vertices = identity."""
        if self._assembler is not None:
            return self._assembler.system(self._vertices, self.mass, self.tau)
        L = self.laplacian()
        L.data *= np.repeat(self.tau / self.mass, np.diff(L.indptr))
        A = (L + sp.identity(L.shape[0], format="csr")).tocsr()
        return dirichlet_rows(A, self.fixed) if self.mesh.has_boundary else A

    def step(self):
        """Advance one time step, (C3).

        Returns
        -------
        ddfv.solver.SolveInfo

        Raises
        ------
        ddfv.stepping.FlowBreakdown
            BiCGStab did not converge (the state stays at ``n - 1``) or the
            new surface is degenerate (the state is the degenerate ``X^n``).
        """
        A = self.system()
        x0 = 2.0 * self._X - self._X_prev
        X, info = bicgstab(A, self._X, x0, rtol=self.rtol, maxiter=self.maxiter)
        if not info.converged:
            raise FlowBreakdown.solver_failed(self.n + 1, self.tau, info, self.rtol)
        self._X_prev, self._X = self._X, X
        self.n += 1
        for name in ("_vertices", "double_areas", "mass"):
            self.__dict__.pop(name, None)
        self._check_geometry()
        return info

    def _check_geometry(self):
        if not np.isfinite(self._X).all():
            raise FlowBreakdown.degenerated(self.n, self.tau, "non-finite coordinates")
        area = self.double_areas
        what = collapsed_cells(area, _COLLAPSED * area.mean(), "triangle")
        if what:
            raise FlowBreakdown.degenerated(self.n, self.tau, what)


@dataclass
class Trajectory:
    """Result of :func:`simulate`.

    Attributes
    ----------
    V : (frames, n, 3) float array
        Frame 0 is the initial surface, the last frame the final (or last
        computed) one.
    t : (frames,) float array
    steps : (frames,) int array
        Time level of each frame.
    iterations : (n_steps,) int array
        BiCGStab iterations of each completed step.
    faces : (m, 3) int array
    status : str
        ``"ok"``, ``"solver_failed"`` or ``"degenerated"``.
    message : str
        Empty when ``status == "ok"``.
    failed_step : int
        Time step of the breakdown, ``-1`` when ``status == "ok"``.
    """

    V: np.ndarray
    t: np.ndarray
    steps: np.ndarray
    iterations: np.ndarray
    faces: np.ndarray
    status: str = "ok"
    message: str = ""
    failed_step: int = -1


def simulate(vertices, faces, tau, steps, *, save_every=1, mass="barycentric",
             rtol=DEFAULT_RTOL, maxiter=1000, assembly="cached", observer=None):
    """Run the cotangent flow (C3) for ``steps`` time steps.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
        Consistently oriented manifold surface; boundary vertices, if any,
        stay fixed.
    tau : float
    steps : int
    save_every : int
        Keep every ``save_every``-th time level as a frame (the first and
        the last are always kept); ``0`` keeps only those two.
    mass, rtol, maxiter, assembly
        See :class:`Flow`.
    observer : callable, optional
        ``observer(flow)`` is called at every time level, ``n = 0`` included.

    Returns
    -------
    Trajectory
        On a breakdown, ``status`` and ``message`` say what happened and
        everything computed before is kept.

    Raises
    ------
    ValueError
        Bad parameters or input mesh (non-manifold, degenerate, ...).

    Examples
    --------
    >>> V, F = icosphere(2)
    >>> traj = simulate(V, F, 0.01, 4, save_every=2)
    >>> traj.status, traj.steps.tolist()
    ('ok', [0, 2, 4])
    """
    flow = Flow(vertices, faces, tau, mass=mass, rtol=rtol, maxiter=maxiter,
                assembly=assembly)
    run = run_steps(flow, steps, save_every=save_every, observer=observer,
                    state=lambda f: (f.V.copy(),))
    (V,) = run.frames
    return Trajectory(V=V, t=run.steps * flow.tau, steps=run.steps,
                      iterations=run.iterations, faces=flow.faces, status=run.status,
                      message=run.message, failed_step=run.failed_step)


def sphere_run(level, *, tau=None, t_final=T_FINAL, radius=1.0, **options):
    """Run the cotangent flow on the icosphere of ``level``: one baseline row.

    Same experiment as :func:`ddfv.sphere.sphere_run` (Section 3.1): the
    icosphere refined ``level`` times, ``tau = 0.04 / 4**(level - 1)`` by
    default, error :class:`ddfv.errors.SphereL2Error` over the vertices
    weighted by the lumped mass.

    Parameters
    ----------
    level : int
    tau : float, optional
    t_final : float
        Must be a whole multiple of ``tau``.
    radius : float
    **options
        Passed to :class:`Flow` (``mass``, ``rtol``, ``maxiter``, ``assembly``).

    Returns
    -------
    ddfv.sphere.SphereRun
        ``variant`` = the mass matrix, ``nV = nF`` = number of vertices,
        ``nT = 0``, ``t_min_barycentric = NaN`` and an empty ``t_monitor``
        (no T-vertices); ``cpu_seconds`` and ``wall_seconds`` time the flow
        and the error.
    """
    tau = level_time_step(level) if tau is None else float(tau)
    steps = time_steps(t_final, tau)
    V, F = icosphere(level, radius)
    error = SphereL2Error(radius)
    cpu, wall = time.process_time(), time.perf_counter()
    traj = simulate(V, F, tau, steps, save_every=0, observer=error, **options)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    ok = traj.status == "ok"
    return SphereRun(
        level=int(level), variant=options.get("mass", "barycentric"),
        nV=len(V), nF=len(V), nT=0, tau=tau, N=steps,
        l2_error=error.value if ok else float("nan"),
        iterations=int(traj.iterations.sum()), cpu_seconds=cpu, wall_seconds=wall,
        status=traj.status,
        t_failed=float("nan") if ok else traj.failed_step * tau,
        t_min_barycentric=float("nan"), message=traj.message)
