"""What every vertex-based baseline shares: the state, the flow contract, the checks.

:class:`VertexFlow` holds the mesh vertices ``X`` (3, n) of a scheme whose
unknowns are the vertices (:mod:`baselines.cotan`, :mod:`baselines.bgn`,
:mod:`baselines.mdr`, :mod:`baselines.deturck`, :mod:`baselines.kll`,
:mod:`baselines.cotan_intrinsic`, :mod:`baselines.cmcf` through the cotangent
scheme): the contract of ``mcfbench.running.flow.SchemeFlow``, the warm start
and the checks of a state (:meth:`VertexFlow.defects`), with the operators of
:mod:`baselines.laplacian` at any state the integrator asks for.
"""

import time
from functools import cached_property

import numpy as np

from kept_factor.threads import check_threads, for_threads

from .kernels import neighbour_cosines
from .laplacian import CotanAssembler
from .mesh import edge_mesh

COLLAPSED = 1e-10
"""A triangle whose area fell below this times the mean area has collapsed."""


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
    threads : int
        Threads of the compiled passes over the triangles and vertices (the
        geometry, the system's rows, the checks; :mod:`kept_factor.threads`): the
        same numbers bit for bit on any count.

    Attributes
    ----------
    n : int
        Current time level.
    tau : float
    timings : dict
        Seconds spent in ``"assembly"`` (geometry and system); the integrator
        adds ``"solve"``.
    """

    def __init__(self, vertices, faces, tau, *, mass="barycentric", threads=1):
        check_threads(threads)
        self.threads = threads
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
                                       self._needs_laplacian() and self._assembles_here,
                                       self.threads)

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
            return self.assembler.geometry(at.T, self._needs_laplacian(), self.threads)
        if self.geometry.L_data is None and self._needs_laplacian():
            self.geometry = self.assembler.geometry(at.T, True, self.threads)  # and L
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
        for_threads(neighbour_cosines, self.threads)(
            self.geometry.area_vectors, self.mesh.face_neighbours, cosine, double_areas)
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
        # area.mean() without its Python wrapper: the same pairwise sum and division
        threshold = max(COLLAPSED * (np.add.reduce(area) / len(area)),
                        1e-2 * COLLAPSED * self._area0)
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
