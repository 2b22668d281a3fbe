"""The cotangent scheme on the intrinsic Delaunay triangulation (Sharp and Crane 2020).

Dziuk's semi-implicit scheme (C1) of :mod:`baselines.cotan`,

    (M^{n-1} + tau L^{n-1}) X^n = M^{n-1} X^{n-1},

with ``L`` and ``M`` the cotangent stiffness and the lumped mass of the
*intrinsic Delaunay triangulation* of the surface ``X^{n-1}`` instead of
those of its mesh: N. Sharp, K. Crane, "A Laplacian for Nonmanifold Triangle
Meshes", Computer Graphics Forum 39(5) (SGP 2020), the "tufted Laplacian":
the cotangent Laplacian of an intrinsic Delaunay triangulation, reached by
edge flips on the intrinsic edge lengths (Bobenko and Springborn, Discrete
Comput. Geom. 38 (2007)), of the "tufted cover" of the mesh, after an
intrinsic mollification of near-degenerate triangles. On a closed manifold
mesh the tufted cover is two copies of the surface glued along its edges and
the tufted Laplacian is the intrinsic Delaunay Laplacian of the surface; on a
mesh with boundary the two copies are also glued along the boundary, whose
edges may then flip as well (the paper's nonnegative boundary weights). The
triangulation has the same vertices and the same piecewise flat metric as
the mesh but other edges wherever the mesh is not Delaunay (opposite angles
summing to more than pi), so that every edge weight ``(cot alpha + cot
beta) / 2`` is >= 0: ``L`` is an M-matrix. Both are built by the
``robust-laplacian`` package (``robust_laplacian.mesh_laplacian``, the
authors' implementation), anew at every step, at the state the integrator
chooses (``X*``, :mod:`mcfbench.running.integrators`).

Conventions of ``mesh_laplacian(V, F, mollify_factor)`` (checked by
``tests/baselines/test_cotan_intrinsic.py``): ``L`` is the positive
semi-definite weak Laplacian (``-igl.cotmatrix`` on a Delaunay mesh), ``M``
the diagonal *barycentric* lumped mass of the intrinsic triangulation (a
third of the areas of its triangles at each vertex; not the Voronoi mass),
so that on a Delaunay mesh the scheme is :class:`baselines.cotan.CotanFlow`
with ``mass="barycentric"`` (registry ``cotan``) to round-off.
``mollify_factor`` ``delta`` (relative to the mean edge length): every edge
length grows by the smallest ``epsilon >= 0`` with which every triangle
satisfies the triangle inequality by ``delta`` times the mean edge length
(the paper's intrinsic mollification); zero on a mesh without such
near-degenerate triangles.

Where the mesh already is the package's triangulation and no triangle is
mollified, the package's operators are the mesh's cotangent stiffness and
barycentric mass (Bobenko and Springborn: the intrinsic Delaunay triangulation
is reached by flipping the edges of negative weight, and there are none),
which the compiled assembly of :class:`baselines.laplacian.CotanAssembler` gives in
a fraction of the package's time; elsewhere the package's flips (and
mollification) are done by a compiled loop on the mesh's edge lengths
(:func:`flip_to_delaunay`), whose triangulation's operators are assembled in a
CSR pattern that grows with the edges the flips make (:class:`FlipPattern`). A
step takes them when :func:`flip_to_delaunay` finds them, the package's call
otherwise (baselines/README.md, "Deviations and interpretations").

The step is solved in the row-scaled form (C3), ``(I + tau diag(1/M) L) X^n
= X^{n-1}`` (:func:`baselines.kernels.row_scaled_system`,
:func:`baselines.laplacian.row_scaled_matrix` for the package's ``L``), with
identity rows at boundary vertices (held fixed, Dirichlet). The state, the checks of a state (on the mesh's
own triangles: an inverted or collapsed mesh triangle ends a run as for
``cotan``) and the L2 weights (the mesh's barycentric lumped mass, the same
total area) are those of :class:`baselines.vertex_flow.VertexFlow`.
"""

import dataclasses

import numpy as np
import robust_laplacian
from numba import njit

from .laplacian import CotanAssembler, row_scaled_matrix
from .vertex_flow import VertexFlow

MOLLIFY = 1e-5
"""The package's default ``mollify_factor`` (baselines/README.md, "Deviations and
interpretations")."""
FLIP_BELOW = -1e-6
"""The package flips an edge of the tufted cover whose weight ``(cot alpha + cot beta) / 2``
is below this (geometry-central's ``flipToDelaunay``, ``delaunayEPS = 1e-6``; measured on
a planar quad: weight -8e-7 kept, -1.2e-6 flipped)."""


def intrinsic_operators(vertices, faces, mollify=MOLLIFY):
    """Stiffness and lumped mass of the intrinsic Delaunay triangulation.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    mollify : float
        ``mollify_factor`` of ``robust_laplacian.mesh_laplacian``, >= 0.

    Returns
    -------
    L : (n, n) scipy.sparse.csr_matrix
        Symmetric, positive semi-definite, zero row sums, edge weights >= 0.
    mass : (n,) float array
        Positive, sums to the area.
    """
    L, M = robust_laplacian.mesh_laplacian(
        np.ascontiguousarray(vertices, dtype=np.float64),
        np.ascontiguousarray(faces, dtype=np.int64), float(mollify))
    return L.tocsr(), np.asarray(M.diagonal())


MARGIN = 1e-12
"""Distance from :data:`FLIP_BELOW` within which an edge weight is left to the package,
times ``1 + (|h1| + |h2|)^3`` for its halves ``h1``, ``h2`` (round-off could put its
weight on the other side there: a few ulps of each half's Heron area, whose relative
error grows as the square of a half cotangent on a sliver)."""


@njit(cache=True)
def flip_to_delaunay(V, faces, edges, edge_faces, face_edges, mollify, indptr, indices,
                     diag_slots, edge_slots, tri, ends, slots, L_data, mass):
    """The intrinsic operators of the package, by its flips compiled.

    The package (geometry-central's ``flipToDelaunay``, Sharp and Crane 2020, Section
    4; N. Sharp, Y. Soliman, K. Crane, "Navigating Intrinsic Triangulations", ACM
    Trans. Graph. 38(4) 2019, Section 3.2; M. Fisher, B. Springborn, P. Schroeder,
    A. Bobenko, "An Algorithm for the Construction of Intrinsic Delaunay
    Triangulations with Applications to Digital Geometry Processing", Computing 81
    (2007), Algorithm 1) puts every edge of the tufted cover in a queue and, edge
    by edge, flips one whose weight ``(cot alpha + cot beta) / 2`` is below
    :data:`FLIP_BELOW`, giving it the length of its two triangles unfolded in the
    plane, and queues the four edges of its quad; it stops when the queue is
    empty, every weight at or above the threshold (Bobenko and Springborn 2007:
    the intrinsic Delaunay triangulation). An interior edge of the cover has the
    mesh edge's weight, a boundary edge twice it (its one angle on both sheets).
    This is that loop on the mesh's edges, in their order, after the package's
    mollification (``mollifyIntrinsic``: every length grows by ``epsilon = max(0,
    max_T (l_c - l_a - l_b) + delta)``, ``delta = mollify`` x the mean edge length;
    Sharp and Crane 2020, Section 4.5).

    The package is needed (-1) when: a triangle has no area even mollified (or a
    length is not finite); a weight the loop reads is within :data:`MARGIN`
    (relative) of the threshold (round-off could decide it the other way); a
    boundary edge would flip; a flip would join a vertex to itself or make a
    triangle of no area; more than 20 E flips. Else every decision is the package's, and so is the
    triangulation where the order of the flips does not matter: it may only in a
    nearly cocircular quad (both diagonals' weights above the threshold), whose
    diagonal a flip beside it could leave either way; the package's order is its
    own on each sheet of the cover, so this is checked, not guaranteed: along the
    flows of the real meshes the operators are the package's to round-off (tested)
    and the reverse order gives the same (measured; baselines/README.md,
    "Deviations and interpretations", item 8).

    Edges keep their index through flips (the edge ``(a, b)`` between ``(a, b, c)``
    and ``(b, a, d)`` becomes ``(c, d)``, the triangles ``(a, d, c)`` and ``(b, c,
    d)``); the stiffness (C2) and barycentric mass of the final triangulation are
    assembled from its edge lengths (:func:`_face`) into the pattern.

    Parameters
    ----------
    V : (n, 3) float64 array
    faces, edges, edge_faces, face_edges : int64 arrays of :class:`baselines.mesh.EdgeMesh`
    mollify : float
    indptr, indices : (n + 1,) and (nnz,) int32 arrays
        The pattern's CSR (column indices sorted within rows).
    diag_slots : (n,) int64 array
    edge_slots : (E, 2) int64 array
        The pattern's slots of the mesh's edges.
    tri : (m, 3) int64 array, output
        The final triangles.
    ends : (E, 2) int64 array, output
        The final edges, ``ends[e, 0] < ends[e, 1]``.
    slots : (E, 2) int64 array, output
        Their slots in the pattern, ``-1`` where it has none.
    L_data : (nnz,) float64 array, output
        The stiffness of the final triangulation (written at status 1).
    mass : (n,) float64 array, output
        Its barycentric lumped mass (written at status 1).

    Returns
    -------
    status : int
        1: ``L_data`` and ``mass`` written; 0: no flip and no mollification, the
        mesh's own operators are the package's (nothing written); -1: the package
        is needed; -2: an edge is not in the pattern (``slots``).
    flips : int
    epsilon : float
        The mollification's growth of the lengths.
    """
    E, m = edges.shape[0], faces.shape[0]
    lengths = np.empty(E)
    total = 0.0
    for e in range(E):
        lengths[e] = _distance(V, edges[e, 0], edges[e, 1])
        total += lengths[e]
    worst, flips = -np.inf, 0
    for t in range(m):
        x, y, z = lengths[face_edges[t, 0]], lengths[face_edges[t, 1]], lengths[face_edges[t, 2]]
        worst = max(worst, 2.0 * max(x, y, z) - (x + y + z))
    epsilon = max(0.0, worst + mollify * (total / E))       # mollifyIntrinsic
    if not worst < epsilon:                                  # no area even mollified, NaN
        return -1, flips, epsilon
    lengths += epsilon
    tri[:] = faces
    sides = face_edges.copy()
    cot, area = np.empty((m, 3)), np.empty(m)        # each corner's half cotangent, area
    for t in range(m):
        _face(lengths, sides, t, cot, area)
    owners = edge_faces.copy()
    ends[:] = edges
    queue = np.arange(E)                      # a ring: every edge at most once in it
    queued = np.ones(E, dtype=np.bool_)
    head, tail, size = 0, 0, E                # pop at head, push at tail (mod E)
    while size > 0:
        e = queue[head]
        head, size = (head + 1 if head + 1 < E else 0), size - 1
        queued[e] = False
        f1, f2 = owners[e, 0], owners[e, 1]
        h1 = cot[f1, _corner_of(sides, f1, e)]
        h2 = h1 if f2 < 0 else cot[f2, _corner_of(sides, f2, e)]
        w, scale = h1 + h2, abs(h1) + abs(h2)
        if not abs(w - FLIP_BELOW) > MARGIN * (1.0 + scale ** 3) or (f2 < 0 and w < FLIP_BELOW):
            return -1, flips, epsilon
        if w >= FLIP_BELOW:
            continue
        k = _corner_of(sides, f1, e)
        c, a, b = tri[f1, k], tri[f1, (k + 1) % 3], tri[f1, (k + 2) % 3]
        bc, ac = sides[f1, (k + 1) % 3], sides[f1, (k + 2) % 3]
        j = _corner_of(sides, f2, e)
        d = tri[f2, j]
        ad, bd = (sides[f2, (j + 1) % 3], sides[f2, (j + 2) % 3]) if tri[f2, (j + 1) % 3] == b \
            else (sides[f2, (j + 2) % 3], sides[f2, (j + 1) % 3])
        flips += 1
        if c == d or flips > 20 * E:
            return -1, flips, epsilon
        tri[f1, 0], tri[f1, 1], tri[f1, 2] = a, d, c          # (a, d, c), (b, c, d)
        sides[f1, 0], sides[f1, 1], sides[f1, 2] = e, ac, ad
        tri[f2, 0], tri[f2, 1], tri[f2, 2] = b, c, d
        sides[f2, 0], sides[f2, 1], sides[f2, 2] = e, bd, bc
        owners[ad, 0 if owners[ad, 0] == f2 else 1] = f1
        owners[bc, 0 if owners[bc, 0] == f1 else 1] = f2
        ends[e, 0], ends[e, 1] = min(c, d), max(c, d)
        lengths[e] = _unfolded(lengths[e], lengths[ac], lengths[bc], lengths[ad], lengths[bd])
        _face(lengths, sides, f1, cot, area)
        _face(lengths, sides, f2, cot, area)
        if not (area[f1] > 0.0 and area[f2] > 0.0):
            return -1, flips, epsilon
        for s in (ac, ad, bd, bc):
            if not queued[s]:
                queue[tail] = s
                tail, size = (tail + 1 if tail + 1 < E else 0), size + 1
                queued[s] = True
    if flips == 0 and epsilon == 0.0:
        return 0, 0, 0.0
    missing = False
    for e in range(E):
        p, q = ends[e, 0], ends[e, 1]
        if p == edges[e, 0] and q == edges[e, 1]:
            slots[e, 0], slots[e, 1] = edge_slots[e, 0], edge_slots[e, 1]
        else:
            slots[e, 0], slots[e, 1] = _slot(indptr, indices, p, q), _slot(indptr, indices, q, p)
            missing = missing or slots[e, 0] < 0
    if missing:
        return -2, flips, epsilon
    L_data[:] = 0.0
    mass[:] = 0.0
    for t in range(m):
        for k in range(3):           # the edge opposite corner k: cotangent weight (C2)
            s, w = sides[t, k], cot[t, k]
            p, q = tri[t, (k + 1) % 3], tri[t, (k + 2) % 3]
            L_data[slots[s, 0]] -= w
            L_data[slots[s, 1]] -= w
            L_data[diag_slots[p]] += w
            L_data[diag_slots[q]] += w
            mass[tri[t, k]] += area[t] / 3.0      # barycentric
    return 1, flips, epsilon


@njit(cache=True, inline="always")
def _distance(V, p, q):
    dx, dy, dz = V[p, 0] - V[q, 0], V[p, 1] - V[q, 1], V[p, 2] - V[q, 2]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, inline="always")
def _corner_of(sides, t, e):
    """The corner of triangle ``t`` opposite its edge ``e``."""
    return 0 if sides[t, 0] == e else (1 if sides[t, 1] == e else 2)


@njit(cache=True, inline="always")
def _area(x, y, z):
    """Heron's area of the triangle of sides ``x, y, z``."""
    return 0.25 * np.sqrt(max((x + y + z) * (-x + y + z) * (x - y + z) * (x + y - z), 0.0))


@njit(cache=True, inline="always")
def _face(lengths, sides, t, cot, area):
    """Triangle ``t``'s area (Heron's) and the half cotangents of its corners, ``cot[t,
    k] = (y^2 + z^2 - x^2) / (8 area)`` for the side ``x`` opposite corner ``k`` (C2)."""
    x, y, z = lengths[sides[t, 0]], lengths[sides[t, 1]], lengths[sides[t, 2]]
    a = _area(x, y, z)
    area[t] = a
    cot[t, 0] = (y * y + z * z - x * x) / (8.0 * a)
    cot[t, 1] = (z * z + x * x - y * y) / (8.0 * a)
    cot[t, 2] = (x * x + y * y - z * z) / (8.0 * a)


@njit(cache=True, inline="always")
def _unfolded(l_ab, l_ac, l_bc, l_ad, l_bd):
    """``|c - d|`` with the triangles ``(a, b, c)`` and ``(b, a, d)`` laid out in the plane
    on either side of ``ab``: the length of the edge the flip of ``ab`` makes."""
    xc = (l_ab ** 2 + l_ac ** 2 - l_bc ** 2) / (2.0 * l_ab)
    xd = (l_ab ** 2 + l_ad ** 2 - l_bd ** 2) / (2.0 * l_ab)
    yc = np.sqrt(max(l_ac ** 2 - xc ** 2, 0.0))
    yd = np.sqrt(max(l_ad ** 2 - xd ** 2, 0.0))
    return np.hypot(xc - xd, yc + yd)


@njit(cache=True, inline="always")
def _slot(indptr, indices, row, col):
    """The slot of ``(row, col)`` in a CSR pattern (sorted columns), ``-1`` if none."""
    lo, hi = indptr[row], indptr[row + 1]
    while lo < hi:
        mid = (lo + hi) // 2
        if indices[mid] < col:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < indptr[row + 1] and indices[lo] == col else -1


class FlipPattern:
    """The package's triangulation by compiled flips, in a CSR pattern that grows.

    The pattern holds the mesh's edges, the diagonal and every edge a flipped
    triangulation has had so far (:func:`flip_to_delaunay`); it grows, rebuilt, when
    a triangulation has an edge it lacks (rarely along a flow: its edges recur), and
    the entries of edges not in the present triangulation hold 0 (no weight).

    Parameters
    ----------
    mesh : baselines.mesh.EdgeMesh
    """

    def __init__(self, mesh):
        self.mesh = mesh
        self._mesh_keys = self._keys = mesh.edges[:, 0] * mesh.n_vertices + mesh.edges[:, 1]
        self._grow(self._mesh_keys)
        self.flip_count = 0
        """The flips of the last :meth:`flip`."""
        self.epsilon = 0.0
        """The mollification's growth of the lengths in the last :meth:`flip`."""

    def _grow(self, keys):
        """Rebuild the pattern with the edges ``a * n + b`` (``a < b``) added."""
        mesh, n = self.mesh, self.mesh.n_vertices
        union = np.union1d(self._keys, keys)
        mine = np.searchsorted(union, self._mesh_keys)
        # laplacian_pattern reads the edges, the vertex count and face_edges
        graph = dataclasses.replace(mesh, edges=np.stack([union // n, union % n], axis=1),
                                    face_edges=mine[mesh.face_edges])
        self._keys = union
        self._assembler = CotanAssembler(graph)       # its CSR of the pattern, row scaling
        self.pattern = self._assembler.pattern
        self.edge_slots = self.pattern.edge_slots[mine]

    def flip(self, vertices, mollify=MOLLIFY):
        """The package's operators, by compiled flips (:func:`flip_to_delaunay`); None
        when the package is needed.

        Parameters
        ----------
        vertices : (n, 3) float array
        mollify : float

        Returns
        -------
        (flip, L_data, mass) or None
            ``flip`` (k,) the edges whose ends the flips changed (rows of
            ``mesh.edges``); ``L_data`` (nnz,) in this pattern and ``mass`` (n,)
            the final triangulation's; both None when nothing flips (the mesh is
            the package's triangulation, its operators are the mesh's own).
        """
        mesh = self.mesh
        V = np.ascontiguousarray(vertices, dtype=np.float64)
        tri, ends = np.empty_like(mesh.faces), np.empty_like(mesh.edges)
        slots = np.empty_like(mesh.edges)
        while True:
            p = self.pattern
            L_out, mass_out = np.empty(p.nnz), np.empty(mesh.n_vertices)
            status, self.flip_count, self.epsilon = flip_to_delaunay(
                V, mesh.faces, mesh.edges, mesh.edge_faces, mesh.face_edges, float(mollify),
                p.indptr, p.indices, p.diag_slots, self.edge_slots, tri, ends, slots, L_out,
                mass_out)
            if status != -2:
                break
            self._grow(ends[slots[:, 0] < 0] @ np.array([mesh.n_vertices, 1]))
        if status < 0:
            return None
        if status == 0:
            return np.empty(0, dtype=np.int64), None, None
        return np.flatnonzero((ends != mesh.edges).any(axis=1)), L_out, mass_out

    def laplacian(self, L_data):
        """``L`` as CSR from the ``L_data`` of :meth:`flip`."""
        return self._assembler.laplacian(L_data)

    def row_scaled(self, L_data, mass, tau, fixed):
        """``I + tau diag(1/M) L`` (C3) as CSR in this pattern; rows ``fixed`` = identity."""
        return self._assembler.row_scaled(L_data, mass, tau, fixed)


class IntrinsicCotanFlow(VertexFlow):
    """Cotangent mean curvature flow (C1) with the intrinsic Delaunay Laplacian.

    Parameters
    ----------
    vertices : (n, 3) float array
        Initial surface ``X^0``.
    faces : (m, 3) int array
        Consistently oriented triangles of a manifold surface, closed or with
        boundary (boundary vertices keep their position).
    tau : float
        Time step.
    mollify : float
        ``mollify_factor`` of :func:`intrinsic_operators`, finite and >= 0.

    Examples
    --------
    >>> V = np.array([[1., 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])   # tetrahedron
    >>> F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    >>> A, b = IntrinsicCotanFlow(V, F, 0.01).system()
    >>> A.shape, b.shape
    ((4, 4), (3, 4))
    """

    def __init__(self, vertices, faces, tau, *, mollify=MOLLIFY):
        if not (np.isfinite(mollify) and mollify >= 0):
            raise ValueError(f"mollify must be a finite number >= 0, got {mollify!r}")
        self.mollify = float(mollify)
        self.delaunay_steps = 0
        """Systems assembled with the mesh's operators (no edge to flip)."""
        self.flipped_steps = 0
        """Systems assembled with the mesh's edges flipped (:func:`flip_to_delaunay`)."""
        super().__init__(vertices, faces, tau, mass="barycentric")
        self.flips = FlipPattern(self.mesh)

    def operators(self, at=None):
        """``(L, mass)`` of :func:`intrinsic_operators` at the state ``at`` (3, n)
        (default the current one), CSR and (n,): from the mesh where it is the
        package's triangulation or the compiled flips reach it
        (:meth:`FlipPattern.flip`), the package's otherwise."""
        at = self._X if at is None else at
        found = self._mesh_operators(at)
        if found is None:
            return intrinsic_operators(at.T, self.faces, self.mollify)
        g, flipped = found
        if flipped is None:
            return self.assembler.laplacian(g.L_data), g.mass
        return self.flips.laplacian(flipped[0]), flipped[1]

    def _mesh_operators(self, at):
        """``(geometry, flipped)`` at ``at``: the mesh's :class:`baselines.laplacian.SurfaceGeometry`
        when the package flips no edge (``flipped`` None), else ``(None, (L_data, mass))`` of
        :meth:`FlipPattern.flip`; None when the package is needed (a degenerate mesh
        triangle is within the mollification's margin: :func:`flip_to_delaunay`)."""
        found = self.flips.flip(at.T, self.mollify)
        if found is None:
            return None
        flip, L_data, mass = found
        if len(flip) == 0 and L_data is None:
            return self.geometry_at(at), None
        return None, (L_data, mass)

    def _system(self, at, base, dt):
        """``A = I + dt diag(1/M*) L*`` (C3) of the intrinsic operators at ``at``, CSR,
        rows of boundary vertices = identity; ``b = B``."""
        found = self._mesh_operators(at)
        if found is None:
            L, mass = intrinsic_operators(at.T, self.faces, self.mollify)
            return row_scaled_matrix(L, mass, dt, self.fixed), base
        g, flipped = found
        if flipped is None:
            self.delaunay_steps += 1
            return self.assembler.row_scaled(g.L_data, g.mass, dt, self.fixed), base
        self.flipped_steps += 1
        return self.flips.row_scaled(*flipped, dt, self.fixed), base
