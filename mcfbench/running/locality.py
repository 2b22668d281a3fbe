"""The vertex and face order for locality, applied once at a run's intake and undone
on everything the run returns (issue #46, item 3).

A refined mesh (the icosphere's refinement puts each level's new vertices after the
old ones) numbers neighbours far apart, so that every sparse product, assembly pass
and solver iteration of a large mesh jumps through memory. :func:`locality_order`
renumbers the vertices by reverse Cuthill-McKee on their adjacency
(:func:`scipy.sparse.csgraph.reverse_cuthill_mckee`; Cuthill and McKee 1969, George
1971) and sorts the triangles by their new vertex numbers, smallest first, the
components kept whole. DDFV orders its own unknowns the same way
(:func:`ddfv.topology.locality_order`), not imported here: a run's code identity
(:mod:`mcfbench.running.identity`) would then hold a DDFV module in every scheme's. Each triangle's vertices keep their cyclic order (its orientation).
The flow is built and stepped on the renumbered mesh (:func:`intake`, a
:class:`RenumberedRun`), which gives back everything in the input's numbering:

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
  (the driver's checks, the schemes' own, a scheme's refusal of the mesh) renamed
  into the input's numbering (:meth:`LocalityOrder.sentence`); the components keep
  their numbers, the new order keeping each component's vertices together, the
  components in the input's order (:func:`scipy.sparse.csgraph.connected_components`
  numbers them by their first vertex), but the vertex named as a component's
  example is its first in the new order;
- a flow rebuilt on the components that remain of a run
  (:mod:`mcfbench.running.continuation`) is seen by the caller's observers and
  returned as the flow rebuilt on the input's numbering would be (the kept
  vertices and triangles in their input order).

Below :data:`MIN_VERTICES` a mesh is left in its order: its vectors fit in the
cache, and the renumbering only moves the floating-point sums
(``benchmarks/README.md``, "The vertex order at intake").
"""

import re
from dataclasses import replace

import numpy as np
import scipy.sparse as sp

from mcfbench.geometry.measures import vertex_components

MIN_VERTICES = 20_000
"""Meshes with fewer vertices keep their order (:func:`locality_order`). Measured
through the harness's step (``benchmarks/bench_bound.py --orders input locality``,
``benchmarks/README.md``): on the sphere's level 6 (40 962 vertices) the order takes
cotan's step to 0.73 x and BGN's to 0.87 x; on level 5 (10 242) and below, where a
step's vectors stay in the last-level cache, it gains nothing (1.00-1.05 x)."""


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
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    edges = F[:, [0, 1, 2, 1, 2, 0]].ravel(), F[:, [1, 2, 0, 0, 1, 2]].ravel()
    adjacency = sp.csr_matrix((np.ones(len(edges[0]), dtype=np.int8), edges), shape=(n, n))
    order = reverse_cuthill_mckee(adjacency, symmetric_mode=True).astype(np.int64)
    labels = vertex_components(F, n)[1]
    order = order[np.argsort(labels[order], kind="stable")]   # components kept whole
    corners = np.sort(_inverse(order)[F], axis=1)
    face_order = np.lexsort((corners[:, 2], corners[:, 1], corners[:, 0]))
    return LocalityOrder(order, face_order, np.array(F, copy=True))


def _inverse(order):
    """The inverse of the permutation ``order`` (n,)."""
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return rank


_NAMED = re.compile(r"\b(vertex|triangle) (\d+)\b")
"""A vertex or a triangle named by its number in a sentence (the driver's checks,
the schemes' defects and refusals: ``"vertex 12"``, ``"triangle 7 folded"``)."""


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

    def options(self, options):
        """A flow's options renumbered: ``T0`` (one point per input triangle)."""
        if options.get("T0") is None:
            return options
        return {**options, "T0": np.asarray(options["T0"])[self.faces]}

    def frames(self, frames):
        """Frames of the renumbered mesh stacked on a first axis (the driver's, in the
        initial mesh's layout) in the input's order: ``"vertices"`` by vertex,
        ``"extra_points"`` by triangle."""
        keys = {"vertices": self.vertex_rank, "extra_points": self.face_rank}
        unknown = set(frames) - set(keys)
        if unknown:
            raise ValueError(f"frame arrays {sorted(unknown)} have no known numbering "
                             "(mcfbench.running.locality)")
        return {key: value[:, keys[key]] for key, value in frames.items()}

    def sentence(self, text):
        """``text`` with every ``vertex <i>`` and ``triangle <j>`` of the renumbered
        mesh named by its input number."""
        vertices, faces = self.vertices, self.faces

        def named(match):
            kind, i = match.group(1), int(match.group(2))
            numbers = vertices if kind == "vertex" else faces
            return f"{kind} {int(numbers[i])}" if i < len(numbers) else match.group(0)

        return _NAMED.sub(named, text) if isinstance(text, str) else text


class RenumberedRun:
    """One execution of a run on the renumbered mesh: what it builds its flow with,
    and the way back to the input's numbering.

    Parameters
    ----------
    order : LocalityOrder
    scheme : registry entry
        Its ``make`` builds the flow.
    mesh : (vertices, faces)
        The input's.
    options : dict
        The flow's options (the input's numbering).
    observers : sequence of callables
        The caller's: called with the flow in the input's order (:class:`InputOrder`).

    Attributes
    ----------
    mesh : (vertices, faces)
        Renumbered (:meth:`LocalityOrder.mesh`).
    options : dict
        Renumbered (:meth:`LocalityOrder.options`).
    observers : list of callables
    kept, kept_faces : int arrays
        The renumbered mesh's vertices and triangles in the current flow (all of them
        until a component vanishes and the flow is rebuilt on the rest, :meth:`rebuild`).
    """

    def __init__(self, order, scheme, mesh, options, observers):
        self.order, self.scheme = order, scheme
        self.mesh, self.options = order.mesh(*mesh), order.options(options)
        self.observers = [self._observer(observer) for observer in observers]
        self._kept(np.arange(len(order.vertices)), np.arange(len(order.faces)))

    def _kept(self, kept, kept_faces):
        """The current flow's points and the permutations to the input's order: the
        kept input vertices and triangles in their own order (as a run on the input's
        numbering keeps them, :func:`mcfbench.running.continuation.sub_mesh`)."""
        order = self.order
        self.kept, self.kept_faces = kept, kept_faces
        vertex_ids, face_ids = order.vertices[kept], order.faces[kept_faces]
        self.vertex_take, self.face_take = np.argsort(vertex_ids), np.argsort(face_ids)
        self.faces = np.searchsorted(vertex_ids[self.vertex_take],
                                     order.input_faces[face_ids[self.face_take]])

    def make(self, *args, **kwargs):
        """The scheme's ``make``, its refusal naming vertices and triangles in the
        input's numbering (:meth:`LocalityOrder.sentence`; the same exception class)."""
        try:
            return self.scheme.make(*args, **kwargs)
        except Exception as err:
            renamed = self.order.sentence(str(err))
            if renamed == str(err):
                raise
            try:
                again = type(err)(renamed)
            except TypeError:           # an exception class of other arguments
                raise err from None
            raise again from None

    def rebuild(self, rebuild):
        """The driver's ``rebuild`` (:func:`mcfbench.running.continuation.sub_flow`),
        following which points the flow keeps."""
        def rebuilt(flow, keep):
            new = rebuild(flow, keep)
            self._kept(self.kept[keep], self.kept_faces[keep[np.asarray(flow.faces)]
                                                         .all(axis=1)])
            return new

        return rebuilt

    def _observer(self, observer):
        return lambda flow: observer(InputOrder(flow, self))

    def trajectory(self, traj):
        """The :class:`~mcfbench.running.trajectory.Trajectory` of the renumbered flow in
        the input's numbering: frames (the initial mesh's layout), faces, defects' and
        events' sentences, its message, its flow (:class:`InputOrder`), and its
        continuation's."""
        order = self.order
        if traj.frames["vertices"].shape[1] != len(order.vertices) \
                or len(traj.faces) != len(order.faces):
            raise ValueError("the run's mesh changed its size: its frames cannot be given "
                             "back in the input's order (mcfbench.running.locality)")
        named = order.sentence

        def texts(record):
            return {k: named(v) if isinstance(v, str) else v for k, v in record.items()}

        continue_with = traj.continue_with
        return replace(
            traj, frames=order.frames(traj.frames), faces=order.input_faces.copy(),
            message=named(traj.message), defects=[texts(d) for d in traj.defects],
            events=[texts(e) for e in traj.events], flow=InputOrder(traj.flow, self),
            continue_with=None if continue_with is None else
            lambda solver, progress=False: self.trajectory(continue_with(solver, progress)))


class InputOrder:
    """A flow seen in its input's numbering: ``vertices``, ``faces``, ``frame()``,
    and the per-point ``X`` (3, points) and ``l2_weights`` (points,) (mesh vertices,
    then DDFV's T-vertices by triangle); everything else is the flow's. A flow rebuilt
    on the components that remain is seen as one rebuilt on the input's numbering.

    Parameters
    ----------
    flow : mcfbench.running.flow.SchemeFlow
        Stepped on the renumbered mesh.
    run : RenumberedRun
    """

    def __init__(self, flow, run):
        self.stepped, self._run = flow, run

    def __getattr__(self, name):
        return getattr(self.stepped, name)

    @property
    def vertices(self):
        return np.asarray(self.stepped.vertices)[self._run.vertex_take]

    @property
    def faces(self):
        return self._run.faces

    def frame(self):
        frame = self.stepped.frame()
        takes = {"vertices": self._run.vertex_take, "extra_points": self._run.face_take}
        return {key: value[takes[key]] for key, value in frame.items()}

    def _points(self, values):
        run = self._run
        n = len(run.kept)
        points = run.vertex_take if values.shape[-1] == n else \
            np.concatenate([run.vertex_take, n + run.face_take])
        return values[..., points]

    @property
    def X(self):
        return self._points(np.asarray(self.stepped.X))

    @property
    def l2_weights(self):
        return self._points(np.asarray(self.stepped.l2_weights))


class AsGiven:
    """One execution of a run on its mesh as given (no renumbering): the interface of
    :class:`RenumberedRun`, everything passed through."""

    def __init__(self, scheme, mesh, options, observers):
        self.mesh, self.options, self.observers = mesh, options, list(observers)
        self.make = scheme.make

    def rebuild(self, rebuild):
        return rebuild

    def trajectory(self, traj):
        return traj


def intake(order, scheme, mesh, options, observers):
    """One execution of a run: on the mesh renumbered by ``order``
    (:class:`RenumberedRun`) or, for None, as given (:class:`AsGiven`)."""
    return AsGiven(scheme, mesh, options, observers) if order is None else \
        RenumberedRun(order, scheme, mesh, options, observers)


def stepped(flow):
    """The flow stepped by the run behind an :class:`InputOrder` view (the flow itself
    when it is none)."""
    return flow.stepped if isinstance(flow, InputOrder) else flow
