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

    def __init__(self, vertices, faces):
        V = np.asarray(vertices, dtype=float)
        self.faces = np.ascontiguousarray(faces, dtype=np.int64)
        self.count, labels = vertex_components(self.faces, len(V))
        self.labels = np.ascontiguousarray(labels, dtype=np.int64)
        self.face_label = self.labels[self.faces[:, 0]]
        self.neighbours = tuple(np.asarray(t, dtype=np.int64)
                                for t in edge_neighbours(self.faces))
        self.folded0 = ~(neighbour_cosines(V, self.faces, self.neighbours) >= 0.0)
        self._skip = self.folded0.astype(np.uint8)
        self._work = np.empty((3, len(self.faces), 3))
        self._area = np.empty(self.count)
        self._box = np.empty((2, self.count, 3))

    def __call__(self, vertices):
        """The :class:`Measured` of the state ``vertices`` (n, 3)."""
        from mcfbench.geometry.kernels import state_pass  # numba on first use

        V = np.ascontiguousarray(vertices, dtype=np.float64)
        N, R, S = self._work
        area, tangent, folded = state_pass(V, self.faces, self.face_label, self.labels,
                                           *self.neighbours, self._skip, N, R, S,
                                           self._area, self._box)
        box = self._box
        return Measured(float(area), float(np.degrees(np.arctan(tangent))), int(folded),
                        self._area, np.sqrt(((box[1] - box[0]) ** 2).sum(axis=1)))
