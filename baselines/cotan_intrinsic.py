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
a fraction of the package's time; where one round of flips of edges with no
triangle in common reaches it, those flips are applied to the mesh's operators
by a compiled loop over the edges (:func:`one_round_flips`), in a CSR pattern
built once of the mesh's edges and the edges their flips make
(:class:`FlipPattern`). A step takes them when :func:`one_round_flips` finds
them, the package's call otherwise (baselines/README.md, "Deviations and
interpretations").

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


MARGIN = 1e-9
"""Distance from :data:`FLIP_BELOW` within which an edge weight is left to the package
(round-off could put its weight on the other side there)."""


@njit(cache=True)
def one_round_flips(V, faces, edges, edge_faces, face_edges, to_pattern, L_mesh, mass_mesh,
                    mollify, edge_slots, diagonal_slots, indptr, diag_slots, flipped, L_data,
                    mass):
    """The intrinsic operators of the package where one round of flips of edges with no
    triangle in common reaches its triangulation.

    The package flips an edge of the tufted cover whose weight is below
    :data:`FLIP_BELOW`, then the edges around it whose weight fell below. An interior
    edge of the cover has the mesh edge's weight ``w = -L_ab``, a boundary edge twice
    it (its one angle on both sheets). The package is needed (-1) when: a triangle is
    within twice the mollification's margin of degenerate (``la + lb - lc < 2 delta``,
    ``delta = mollify`` x the mean edge length: the package's ``epsilon`` would not be
    0); a weight is within :data:`MARGIN` of the threshold; a boundary edge would flip;
    two edges to flip share a triangle; a flip's new edge is a mesh edge or another
    flip's; after the round an edge is still below the threshold (or within
    :data:`MARGIN` of it; a boundary edge with twice its weight). Else the flips of
    independent edges do not interact and the package stops where none is below: its
    triangulation is the mesh with these edges flipped (Bobenko and Springborn 2007).

    Each edge ``(a, b)`` between the triangles ``(a, b, c)`` and ``(b, a, d)`` becomes
    ``(c, d)``, of the length of the planar unfolding of the two (``|c - d|`` with
    ``c``, ``d`` laid out on either side of ``ab`` from the side lengths); the two
    triangles' cotangent weights (C2) and thirds of their areas (barycentric mass) are
    taken out of the mesh's and those of ``(a, d, c)`` and ``(b, c, d)`` put in
    (:func:`_triangle`), and the entries of ``(a, b)`` set to 0 (no longer an edge).

    Parameters
    ----------
    V : (n, 3) float64 array
    faces, edges, edge_faces, face_edges : int64 arrays of :class:`baselines.mesh.EdgeMesh`
    to_pattern : (nnz_mesh,) int64 array
        The slot in this pattern of each slot of the mesh's.
    L_mesh : (nnz_mesh,) float64 array
        The mesh's cotangent stiffness (C2) at ``V`` in the mesh's pattern.
    mass_mesh : (n,) float64 array
        Its barycentric lumped mass.
    mollify : float
    edge_slots, diagonal_slots : (E, 2) int64 arrays
        Slots of each edge and of the edge its flip makes in the pattern of
        :class:`FlipPattern` (``-1``: the edge does not flip here).
    indptr : (n + 1,) int32 array
    diag_slots : (n,) int64 array
        The pattern's row starts and diagonal slots.
    flipped : (E,) bool array, output
        The edges flipped.
    L_data : (nnz,) float64 array, output
        The stiffness of the flipped triangulation (written when edges flip).
    mass : (n,) float64 array, output
        Its barycentric lumped mass (written when edges flip).

    Returns
    -------
    int
        The number of edges flipped; 0: the mesh is the package's triangulation; -1:
        the package is needed.
    """
    E, m = edges.shape[0], faces.shape[0]
    lengths = np.empty(E)
    total = 0.0
    for e in range(E):
        lengths[e] = _distance(V, edges[e, 0], edges[e, 1])
        total += lengths[e]
    bound = 2.0 * mollify * (total / E)
    for t in range(m):
        x, y, z = lengths[face_edges[t, 0]], lengths[face_edges[t, 1]], lengths[face_edges[t, 2]]
        if not (x + y + z) - 2.0 * max(x, y, z) > bound:
            return -1
    L_data[:] = 0.0
    for p in range(len(L_mesh)):
        L_data[to_pattern[p]] = L_mesh[p]
    on_face = np.zeros(m, dtype=np.bool_)
    taken = np.zeros(len(L_data), dtype=np.bool_)
    k = 0
    for e in range(E):
        boundary = edge_faces[e, 1] < 0
        cover = (2.0 if boundary else 1.0) * -L_data[edge_slots[e, 0]]
        if abs(cover - FLIP_BELOW) <= MARGIN or (boundary and cover < FLIP_BELOW):
            return -1
        if not cover < FLIP_BELOW:
            continue
        f1, f2, new = edge_faces[e, 0], edge_faces[e, 1], diagonal_slots[e, 0]
        if on_face[f1] or on_face[f2] or new < 0 or taken[new]:
            return -1
        on_face[f1] = on_face[f2] = taken[new] = flipped[e] = True
        k += 1
    if k == 0:
        return 0
    mass[:] = mass_mesh
    for e in range(E):
        if not flipped[e]:
            continue
        a, b, f1, f2 = edges[e, 0], edges[e, 1], edge_faces[e, 0], edge_faces[e, 1]
        bc = ac = bd = ad = c = d = -1
        for j in range(3):
            if faces[f1, j] == a:
                bc = face_edges[f1, j]
            elif faces[f1, j] == b:
                ac = face_edges[f1, j]
            else:
                c = faces[f1, j]
            if faces[f2, j] == a:
                bd = face_edges[f2, j]
            elif faces[f2, j] == b:
                ad = face_edges[f2, j]
            else:
                d = faces[f2, j]
        l_ab, l_bc, l_ac = lengths[e], lengths[bc], lengths[ac]
        l_ad, l_bd = lengths[ad], lengths[bd]
        xc = (l_ab ** 2 + l_ac ** 2 - l_bc ** 2) / (2.0 * l_ab)       # c above ab, d below
        xd = (l_ab ** 2 + l_ad ** 2 - l_bd ** 2) / (2.0 * l_ab)
        yc = np.sqrt(max(l_ac ** 2 - xc ** 2, 0.0))
        yd = np.sqrt(max(l_ad ** 2 - xd ** 2, 0.0))
        l_cd = np.hypot(xc - xd, yc + yd)
        # (its corners, the sides opposite them and their edges, -1 taken out / +1 put in)
        _triangle(L_data, mass, diag_slots, -1.0, a, b, c, l_bc, l_ac, l_ab,
                  edge_slots[bc, 0], edge_slots[bc, 1], edge_slots[ac, 0], edge_slots[ac, 1],
                  edge_slots[e, 0], edge_slots[e, 1])
        _triangle(L_data, mass, diag_slots, -1.0, b, a, d, l_ad, l_bd, l_ab,
                  edge_slots[ad, 0], edge_slots[ad, 1], edge_slots[bd, 0], edge_slots[bd, 1],
                  edge_slots[e, 0], edge_slots[e, 1])
        _triangle(L_data, mass, diag_slots, 1.0, a, d, c, l_cd, l_ac, l_ad,
                  diagonal_slots[e, 0], diagonal_slots[e, 1], edge_slots[ac, 0],
                  edge_slots[ac, 1], edge_slots[ad, 0], edge_slots[ad, 1])
        _triangle(L_data, mass, diag_slots, 1.0, b, c, d, l_cd, l_bd, l_bc,
                  diagonal_slots[e, 0], diagonal_slots[e, 1], edge_slots[bd, 0],
                  edge_slots[bd, 1], edge_slots[bc, 0], edge_slots[bc, 1])
        L_data[edge_slots[e, 0]] = L_data[edge_slots[e, 1]] = 0.0
    for i in range(len(mass)):
        for p in range(indptr[i], indptr[i + 1]):
            if p != diag_slots[i] and not -L_data[p] >= FLIP_BELOW + MARGIN:
                return -1
    for e in range(E):
        if edge_faces[e, 1] < 0 and not -2.0 * L_data[edge_slots[e, 0]] >= FLIP_BELOW + MARGIN:
            return -1
    return k


@njit(cache=True, inline="always")
def _distance(V, p, q):
    dx, dy, dz = V[p, 0] - V[q, 0], V[p, 1] - V[q, 1], V[p, 2] - V[q, 2]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


@njit(cache=True, inline="always")
def _triangle(L_data, mass, diag_slots, sign, p0, p1, p2, l0, l1, l2, s0, t0, s1, t1, s2, t2):
    """Add ``sign`` x the cotangent weights (C2) and the thirds of the area of the
    triangle ``(p0, p1, p2)`` of sides ``l0, l1, l2`` (``l_k`` opposite ``p_k``, its
    slots ``s_k, t_k``): ``(l_j^2 + l_k^2 - l_i^2) / (8 area)`` (cotangent / 2), Heron's
    area."""
    x, y, z = l0, l1, l2
    area = 0.25 * np.sqrt(max((x + y + z) * (-x + y + z) * (x - y + z) * (x + y - z), 0.0))
    _edge(L_data, diag_slots, p1, p2, s0, t0, sign * (y * y + z * z - x * x) / (8.0 * area))
    _edge(L_data, diag_slots, p2, p0, s1, t1, sign * (z * z + x * x - y * y) / (8.0 * area))
    _edge(L_data, diag_slots, p0, p1, s2, t2, sign * (x * x + y * y - z * z) / (8.0 * area))
    third = sign * area / 3.0
    mass[p0] += third
    mass[p1] += third
    mass[p2] += third


@njit(cache=True, inline="always")
def _edge(L_data, diag_slots, p, q, s, t, w):
    """Add the weight ``w`` of the edge ``(p, q)`` (its slots ``s``, ``t``) to ``L`` (C2)."""
    L_data[s] -= w
    L_data[t] -= w
    L_data[diag_slots[p]] += w
    L_data[diag_slots[q]] += w


class FlipPattern:
    """The mesh's triangulation one round of flips away from it, compiled.

    The CSR pattern, built once, of the mesh's edges, the diagonal and, for every
    interior edge ``(a, b)`` between the triangles ``(a, b, c)`` and ``(b, a, d)``,
    the edge ``(c, d)`` its flip makes (unless that is a mesh edge: then the edge
    does not flip here). :meth:`flip` writes the intrinsic operators of a round of
    flips into it (:func:`one_round_flips`); the entries of edges that are not in
    the flipped triangulation hold 0 (no weight).

    Parameters
    ----------
    mesh : baselines.mesh.EdgeMesh
    mesh_pattern : baselines.mesh.LaplacianPattern
        The mesh's own pattern, in which :meth:`flip` reads the mesh's stiffness.
    """

    def __init__(self, mesh, mesh_pattern):
        n, F = mesh.n_vertices, mesh.faces
        inner = np.flatnonzero(mesh.edge_faces[:, 1] >= 0)
        f1, f2 = mesh.edge_faces[inner, 0], mesh.edge_faces[inner, 1]
        c = F[f1, np.argmax(mesh.face_edges[f1] == inner[:, None], axis=1)]
        d = F[f2, np.argmax(mesh.face_edges[f2] == inner[:, None], axis=1)]
        keys = mesh.edges[:, 0] * n + mesh.edges[:, 1]                   # sorted (EdgeMesh)
        new = np.minimum(c, d) * n + np.maximum(c, d)
        found = np.minimum(np.searchsorted(keys, new), len(keys) - 1)
        flippable = (c != d) & (keys[found] != new)
        union, where = np.unique(np.concatenate([keys, new[flippable]]), return_inverse=True)
        # laplacian_pattern reads the edges, the vertex count and face_edges
        graph = dataclasses.replace(mesh, edges=np.stack([union // n, union % n], axis=1),
                                    face_edges=where[mesh.face_edges])
        self._assembler = CotanAssembler(graph)       # its CSR of the pattern, row scaling
        self.pattern = self._assembler.pattern
        self.edge_slots = self.pattern.edge_slots[where[:len(keys)]]
        self.diagonal_slots = np.full((mesh.n_edges, 2), -1, dtype=np.int64)
        self.diagonal_slots[inner[flippable]] = self.pattern.edge_slots[where[len(keys):]]
        self.to_pattern = np.empty(mesh_pattern.nnz, dtype=np.int64)
        self.to_pattern[mesh_pattern.edge_slots] = self.edge_slots
        self.to_pattern[mesh_pattern.diag_slots] = self.pattern.diag_slots
        self.mesh = mesh

    def flip(self, vertices, L_data, mass, mollify=MOLLIFY):
        """The package's operators, when one round of flips of the mesh reaches its
        triangulation (:func:`one_round_flips`); None when that is not known.

        Parameters
        ----------
        vertices : (n, 3) float array
        L_data : (nnz,) float array
            The mesh's cotangent stiffness (C2) at ``vertices`` in its pattern
            (:class:`baselines.mesh.LaplacianPattern`).
        mass : (n,) float array
            Its barycentric lumped mass.
        mollify : float

        Returns
        -------
        (flip, L_data, mass) or None
            ``flip`` (k,) the edges flipped (rows of ``mesh.edges``); empty: the mesh
            is the package's triangulation, its operators are the mesh's own
            (``L_data`` and ``mass`` None); else the stiffness in this pattern,
            (nnz,), and the mass, (n,).
        """
        mesh, p = self.mesh, self.pattern
        flipped = np.zeros(mesh.n_edges, dtype=np.bool_)
        L_out, mass_out = np.empty(p.nnz), np.empty(mesh.n_vertices)
        k = one_round_flips(
            np.ascontiguousarray(vertices, dtype=np.float64), mesh.faces, mesh.edges,
            mesh.edge_faces, mesh.face_edges, self.to_pattern, L_data, mass,
            float(mollify), self.edge_slots, self.diagonal_slots, p.indptr, p.diag_slots,
            flipped, L_out, mass_out)
        if k < 0:
            return None
        return (np.flatnonzero(flipped),) + ((L_out, mass_out) if k else (None, None))

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
        """Systems assembled with one round of flips of the mesh (:func:`one_round_flips`)."""
        super().__init__(vertices, faces, tau, mass="barycentric")
        self.flips = FlipPattern(self.mesh, self.assembler.pattern)

    def operators(self, at=None):
        """``(L, mass)`` of :func:`intrinsic_operators` at the state ``at`` (3, n)
        (default the current one), CSR and (n,): from the mesh where it is the
        package's triangulation or one round of flips away from it
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
        and, when the package flips edges, the ``(L_data, mass)`` of :meth:`FlipPattern.flip`
        (None when it flips none); None when the package is needed."""
        g = self.geometry_at(at)
        if g.degenerate:
            return None
        found = self.flips.flip(at.T, g.L_data, g.mass, self.mollify)
        if found is None:
            return None
        flip, L_data, mass = found
        return g, (None if len(flip) == 0 else (L_data, mass))

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
