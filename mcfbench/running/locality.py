"""The vertex and face order for locality, applied once at a run's intake and undone
on everything the run returns (issue #46, item 3).

A refined mesh (the icosphere's refinement puts each level's new vertices after the
old ones) numbers neighbours far apart, so that every sparse product, assembly pass
and solver iteration of a large mesh jumps through memory. :func:`locality_order`
renumbers the vertices by reverse Cuthill-McKee on their adjacency
(:func:`scipy.sparse.csgraph.reverse_cuthill_mckee`; Cuthill and McKee 1969, George
1971) and sorts the triangles by their new vertex numbers, smallest first: DDFV's own
order of its unknowns (:func:`ddfv.topology.locality_order`), the components then
kept whole. Each triangle's vertices keep their cyclic order (its orientation). The flow is built and stepped
on the renumbered mesh; :class:`LocalityOrder` gives back everything in the input's
numbering:

- the frames: mesh vertices in the input's vertex order, DDFV's T-vertices (one per
  triangle) in the input's face order; the trajectory's faces are the input's;
- DDFV's ``T0`` option (one point per triangle) renumbered on the way in: the only
  option of a flow that is per vertex or per face (boundary vertices, fixed
  vertices and weights are computed by each flow from its mesh);
- observers given by the run's caller get a view of the flow in the input's order
  (:class:`InputOrder`); the problems' metric observers
  (:mod:`mcfbench.running.observers`,
  :class:`mcfbench.running.real_mesh_problems.RealMeshShape`) see the renumbered
  flow: each is a sum, an extremum or a surface measure over all the points
  (area, volume, the sphere's error (3.2), heights, the catenoid's profile with
  its own ``fixed``, a displacement from the same flow's initial state), the same
  in any numbering up to the order of the floating-point sums;
- the sentences of defects and events naming ``vertex <i>`` or ``triangle <j>``
  (the driver's checks, the schemes' own) renamed into the input's numbering
  (:meth:`LocalityOrder.sentence`); the components keep their numbers, the
  new order keeping each component's vertices together, the components in the
  input's order (:func:`scipy.sparse.csgraph.connected_components` numbers them
  by their first vertex).

Below :data:`MIN_VERTICES` a mesh is left in its order: its vectors fit in the
cache, and the renumbering only moves the floating-point sums
(``benchmarks/README.md``, "The vertex order at intake").
"""

import re
from dataclasses import replace

import numpy as np

from mcfbench.geometry.measures import vertex_components

MIN_VERTICES = 10_000
"""Meshes with fewer vertices keep their order (:func:`locality_order`): measured
through the harness (``benchmarks/bench_bound.py --order``), the cotan step gains
nothing below about level 5 of the sphere (10 242 vertices)."""


def locality_order(vertices, faces, *, min_vertices=None):
    """The renumbering of a mesh for locality, or None for a mesh kept in its order.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
        A valid mesh (:func:`mcfbench.geometry.mesh.validate_mesh`).
    min_vertices : int, optional
        Meshes of fewer vertices are kept in their order (None returned); default
        :data:`MIN_VERTICES` (read at the call: a benchmark sets it to compare).

    Returns
    -------
    LocalityOrder or None
    """
    F = np.asarray(faces)
    n = len(vertices)
    if n < (MIN_VERTICES if min_vertices is None else min_vertices):
        return None
    from ddfv.topology import locality_order as reverse_cuthill_mckee_order

    order = reverse_cuthill_mckee_order(F, n)[0]
    labels = vertex_components(F, n)[1]
    order = order[np.argsort(labels[order], kind="stable")]   # components kept whole
    corners = np.sort(_inverse(order)[F], axis=1)
    face_order = np.lexsort((corners[:, 2], corners[:, 1], corners[:, 0]))
    return LocalityOrder(order, face_order, np.array(F, copy=True))


def _inverse(order):
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return rank


_NAMED = re.compile(r"\b(vertex|triangle) (\d+)\b")


class LocalityOrder:
    """A mesh's renumbering (:func:`locality_order`).

    Attributes
    ----------
    vertices : (n,) int array
        The input's number of every new vertex (new vertex ``k`` is input vertex
        ``vertices[k]``).
    faces : (m,) int array
        The input's number of every new triangle.
    input_faces : (m, 3) int array
        The input's triangles.

    vertex_rank : (n,) int array
        The new number of every input vertex.
    face_rank : (m,) int array
        The new number of every input triangle.
    """

    def __init__(self, vertices, faces, input_faces):
        self.vertices, self.faces = np.asarray(vertices), np.asarray(faces)
        self.input_faces = np.asarray(input_faces)
        self.vertex_rank, self.face_rank = _inverse(self.vertices), _inverse(self.faces)

    def mesh(self, vertices, faces):
        """The mesh ``(vertices, faces)`` (the input's) renumbered: ``(V', F')``."""
        F = self.vertex_rank[np.asarray(faces)[self.faces]]
        return np.ascontiguousarray(np.asarray(vertices)[self.vertices]), F

    def intake(self, mesh, options, observers):
        """What a run builds its flow with, renumbered: the mesh (:meth:`mesh`), the
        flow's options (:meth:`options`), the caller's observers (:meth:`observer`)."""
        return (self.mesh(*mesh), self.options(options),
                [self.observer(observer) for observer in observers])

    def options(self, options):
        """A flow's options renumbered: ``T0`` (one point per input triangle)."""
        if options.get("T0") is None:
            return options
        return {**options, "T0": np.asarray(options["T0"])[self.faces]}

    def frame(self, frame):
        """A frame of the renumbered flow (:meth:`SchemeFlow.frame`) in the input's
        order: ``"vertices"`` by vertex, ``"extra_points"`` by triangle."""
        return self._undone(frame, 0)

    def _undone(self, frame, axis):
        keys = {"vertices": self.vertex_rank, "extra_points": self.face_rank}
        unknown = set(frame) - set(keys)
        if unknown:
            raise ValueError(f"frame arrays {sorted(unknown)} have no known numbering "
                             "(mcfbench.running.locality)")
        return {key: np.take(value, keys[key], axis=axis) for key, value in frame.items()}

    def sentence(self, text):
        """``text`` with every ``vertex <i>`` and ``triangle <j>`` of the renumbered
        mesh named by its input number."""
        vertices, faces = self.vertices, self.faces

        def named(match):
            kind, i = match.group(1), int(match.group(2))
            numbers = vertices if kind == "vertex" else faces
            return f"{kind} {int(numbers[i])}" if i < len(numbers) else match.group(0)

        return _NAMED.sub(named, text) if isinstance(text, str) else text

    def observer(self, observer):
        """``observer`` called with the flow in the input's order (:class:`InputOrder`)."""
        return lambda flow: observer(InputOrder(flow, self))

    def trajectory(self, traj):
        """The :class:`~mcfbench.running.driver.Trajectory` of the renumbered flow in
        the input's numbering: frames, faces, defects' and events' sentences, its
        message, its flow (:class:`InputOrder`), and its continuation's."""
        if traj.frames["vertices"].shape[1] != len(self.vertices) \
                or len(traj.faces) != len(self.faces):
            raise ValueError("the run's mesh changed its size: its frames cannot be given "
                             "back in the input's order (mcfbench.running.locality)")
        named = self.sentence

        def texts(record):
            return {k: named(v) if isinstance(v, str) else v for k, v in record.items()}

        continue_with = traj.continue_with
        return replace(
            traj, frames=self._undone(traj.frames, 1), faces=self.input_faces.copy(),
            message=named(traj.message), defects=[texts(d) for d in traj.defects],
            events=[texts(e) for e in traj.events], flow=InputOrder(traj.flow, self),
            continue_with=None if continue_with is None else
            lambda solver, progress=False: self.trajectory(continue_with(solver, progress)))


class InputOrder:
    """A flow seen in its input's numbering: ``vertices``, ``faces``, ``frame()``,
    and the per-point ``X`` (3, points) and ``l2_weights`` (points,) (mesh vertices,
    then DDFV's T-vertices by triangle); everything else is the flow's.

    Parameters
    ----------
    flow : mcfbench.running.flow.SchemeFlow
        Stepped on the renumbered mesh.
    order : LocalityOrder
    """

    def __init__(self, flow, order):
        self.stepped, self._order = flow, order

    def __getattr__(self, name):
        return getattr(self.stepped, name)

    @property
    def vertices(self):
        return np.asarray(self.stepped.vertices)[self._order.vertex_rank]

    @property
    def faces(self):
        return self._order.input_faces

    def frame(self):
        return self._order.frame(self.stepped.frame())

    def _points(self, values):
        order = self._order
        n = len(order.vertices)
        points = order.vertex_rank if values.shape[-1] == n else \
            np.concatenate([order.vertex_rank, n + order.face_rank])
        return values[..., points]

    @property
    def X(self):
        return self._points(np.asarray(self.stepped.X))

    @property
    def l2_weights(self):
        return self._points(np.asarray(self.stepped.l2_weights))


def stepped(flow):
    """The flow stepped by the run behind an :class:`InputOrder` view (the flow itself
    when it is none)."""
    return flow.stepped if isinstance(flow, InputOrder) else flow
