"""What the driver's checks read of every state of a flow's mesh, measured in one call.

The collapse check (:class:`mcfbench.geometry.collapse.CollapseCheck`: the area
and the diameter of every connected component) and the invariant checks
(:class:`mcfbench.geometry.invariants.FlowInvariants`: the total area, the
smallest angle, the triangles folded that were not at step 0) of one state read
the same triangles. :class:`StateMeasures` measures all of it with one call of
the compiled :func:`mcfbench.geometry.kernels.state_pass` (one pass over the
triangles, one over the points, one over the pairs of edge-neighbours, into
buffers kept for the whole run), and the driver
(:func:`mcfbench.running.driver.simulate`) hands the one :class:`Measured` of a
state to both checks. Every number is the one the checks computed in separate
passes before (the areas summed in the same order, the same fold count as the
quality monitor's :func:`mcfbench.geometry.kernels.count_folds`).
"""

from typing import NamedTuple

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from mcfbench.geometry.metrics import edge_neighbours, neighbour_cosines


def vertex_components(faces, n):
    """Connected component of every vertex (shared edges or vertices connect).

    Parameters
    ----------
    faces : (m, 3) int array
    n : int
        Number of vertices.

    Returns
    -------
    count : int
    labels : (n,) int array
        Component of each vertex, ``0 .. count - 1`` (a vertex in no triangle
        is a component of its own).
    """
    F = np.asarray(faces, dtype=np.int64)
    rows = np.concatenate([F[:, 0], F[:, 1]])
    cols = np.concatenate([F[:, 1], F[:, 2]])
    graph = coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    count, labels = connected_components(graph, directed=False)
    return int(count), labels


def neighbour_table(t1, t2, m):
    """Every triangle's edge-neighbours in a table, as
    :func:`mcfbench.geometry.kernels.state_pass` gathers them.

    Parameters
    ----------
    t1, t2 : (k,) int arrays
        The pairs of edge-neighbours (:func:`mcfbench.geometry.metrics.edge_neighbours`).
    m : int
        Number of triangles.

    Returns
    -------
    table : (m, w) int64 array
        Row ``t``: the triangles paired with ``t`` where ``t`` is first (in the order
        of the pairs), then those where it is second, padded with ``m``; ``w`` the
        largest count, at least 3 (3 on a manifold mesh).
    split : (m,) int64 array
        How many of row ``t`` pair with ``t`` first.
    """
    owner, other = np.concatenate([t1, t2]), np.concatenate([t2, t1])
    order = np.argsort(owner, kind="stable")
    counts = np.bincount(owner, minlength=m)
    table = np.full((m, max(3, int(counts.max(initial=0)))), m, dtype=np.int64)
    rows = owner[order]
    table[rows, np.arange(len(rows)) - (np.cumsum(counts) - counts)[rows]] = other[order]
    return table, np.bincount(t1, minlength=m).astype(np.int64)


class Measured(NamedTuple):
    """The measures of one state (:meth:`StateMeasures.__call__`).

    The two arrays are the measuring object's buffers, overwritten by its next
    call: a check reads them before the next state is measured.
    """

    area: float
    """Total area of the mesh."""
    angle: float
    """Smallest angle of the triangles, degrees."""
    folded: int
    """Triangles folded against their edge-neighbours that were not at step 0."""
    component_area: np.ndarray
    """(count,) area of every connected component."""
    diameter: np.ndarray
    """(count,) diagonal of every component's bounding box."""


class StateMeasures:
    """The measures of the states of one mesh (fixed triangles, moving points).

    Parameters
    ----------
    vertices : (n, 3) float array
        The initial state: its folded triangles are not counted later.
    faces : (m, 3) int array
        Consistently oriented triangles.
    threads : int
        Threads of the pass (:func:`mcfbench.geometry.kernels.state_pass_threads`; one:
        :func:`mcfbench.geometry.kernels.state_pass`), the same numbers bit for bit.

    Attributes
    ----------
    faces : (m, 3) int64 array
    count : int
        Number of connected components (:func:`vertex_components`).
    labels : (n,) int64 array
        Component of every point.
    face_label : (m,) int64 array
        Component of every triangle.
    neighbours : two (k,) int64 arrays
        The pairs of edge-neighbours (:func:`mcfbench.geometry.metrics.edge_neighbours`).
    folded0 : (m,) bool array
        Triangles folded at step 0 (:func:`mcfbench.geometry.metrics.neighbour_cosines`
        negative or NaN).

    Examples
    --------
    >>> from mcfbench.geometry.spheres import icosphere
    >>> V, F = icosphere(1)
    >>> measured = StateMeasures(V, F)(2.0 * V)
    >>> round(measured.area, 4), round(measured.angle, 4), measured.folded
    (46.6637, 55.569, 0)
    >>> measured.diameter.round(4)
    array([6.9282])
    """

    def __init__(self, vertices, faces, threads=1):
        V = np.asarray(vertices, dtype=float)
        self.threads = threads
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        self.count, labels = vertex_components(self.faces, len(V))
        self.labels = np.ascontiguousarray(labels, dtype=np.int64)
        self.face_label = self.labels[self.faces[:, 0]]
        self.neighbours = tuple(np.asarray(t, dtype=np.int64)
                                for t in edge_neighbours(self.faces))
        self.folded0 = ~(neighbour_cosines(V, self.faces, self.neighbours) >= 0.0)
        self._skip = self.folded0.astype(np.uint8)
        self._table, self._split = neighbour_table(*self.neighbours, len(self.faces))
        self._normals = np.empty((len(self.faces) + 1, 3))
        self._area = np.empty(self.count)
        self._box = np.empty((2, self.count, 3))
        self._diameter = np.empty(self.count)

    def __call__(self, vertices):
        """The :class:`Measured` of the state ``vertices`` (n, 3)."""
        from mcfbench.geometry import kernels  # numba on first use

        # Fortran order: the (n, 3) views of the schemes' (3, n) states as they are (a
        # C-ordered copy of them took 15 us of a 100 us pass at 3 000 vertices), one
        # compiled version for every caller
        V = np.asfortranarray(vertices, dtype=np.float64)
        arguments = (V, self.faces, self.face_label, self.labels, self._table, self._split,
                     self._skip, self._normals, self._area, self._box, self._diameter)
        if self.threads == 1:
            area, tangent, folded = kernels.state_pass(*arguments)
        else:
            m = len(self.faces)
            area, tangent, folded = kernels.state_pass_threads(self.threads, *arguments,
                                                               np.empty(m), np.empty(m))
        return Measured(float(area), float(np.degrees(np.arctan(tangent))), int(folded),
                        self._area, self._diameter)
