"""A run that loses one closed component of several goes on with the rest.

When a component vanishes round (``extinct``, :mod:`mcfbench.geometry.collapse`)
and others remain, the driver (:func:`mcfbench.running.driver.simulate`, its
``rebuild``) drops the component's vertices and triangles and builds the
scheme's flow anew on what remains (:func:`sub_flow`): the positions of the
remaining vertices, and DDFV's T-vertices of the remaining triangles as its
``T0`` (:attr:`mcfbench.running.schemes.Scheme.extra_points`), at the same time
level. That is the same flow only for a scheme whose step depends on its
current state alone; :func:`why_not` names the others, whose runs end
``degenerated`` saying so:

- a tangential strategy that keeps something of the initial state:
  ``conformal`` (conformalized MCF keeps its initial stiffness), ``deturck``
  (its harmonic map heat flow is onto the initial mesh), ``redistribute`` (its
  rate is ``omega 4 pi / A_0``, ``A_0`` the initial area; DDFV's needs a
  connected surface anyway), ``kll`` (its evolved normal and mean curvature
  would be measured again from the mesh);
- an integrator with past states (BDF2, BDF3: ``X^{n-1}, ...`` of the vanished
  vertices, in each flow's own numbering).

A run of ``NAME+remesh`` or ``NAME+surgery`` is none of those: it restarts its scheme
at every change of its mesh (:mod:`mcfbench.running.remeshing`'s rule: the integrator
from its first step, the initial-state strategies from the new surface), a vanished
component's as a remesh's or a cut's.

A run of ``NAME+surgery`` (:attr:`mcfbench.running.scheme.Scheme.mesh_strategy`)
goes on through a neck pinch the same way, every scheme restarted as after a remesh
(:func:`mcfbench.running.surgery.neck_surgery`, the driver's mesh hook
:class:`mcfbench.running.surgery.Surgeon`): once a neck's
radius falls below half the run's resolution
(:func:`mcfbench.geometry.mesh_surgery.pinched`), the neck is cut and both sides
capped (:func:`mcfbench.geometry.mesh_surgery.cut_neck`) and the scheme's flow is
built anew on the operated mesh, DDFV's T-vertices placed anew by its own rule
(the caps' triangles have none to carry; the kept ones are re-initialised too, so
that every T-vertex of the new flow is placed alike). A run whose surgeries removed
more than :data:`MAX_REMOVED_SHARE` of the initial area does not count as reaching
its end (:func:`exceeded`; the record's ``removed_area_share`` and
``surgery_exceeded``). The same run re-extracts its surface without the parts thinner
than the mesh once they are about to fold (:class:`mcfbench.running.surgery.Reextractor`,
:mod:`mcfbench.geometry.reextraction`), its removed area counted alike.
"""

import numpy as np

from mcfbench.running.integrators import INTEGRATORS

MAX_REMOVED_SHARE = 0.01
"""The largest share of the initial area a run's continuations may remove (``|area
removed|`` summed over its neck cuts and re-extractions) for the run to count as
reaching its end: the dumbbell's cuts remove 1.2e-3 to 1.5e-3 of it at level 1,
3.9e-4 to 4.3e-4 at level 2, with the caps' re-extraction 5.2e-3 to 5.4e-3 and 3.8e-4
to 1.9e-3 (cotan, BGN, DDFV chord carried; ``benchmarks/dumbbell_surgery.py``)."""

STATE_ONLY = ("none", "eliminate", "bgn", "mdr", "intrinsic-delaunay")
"""The tangential strategies (:data:`mcfbench.running.schemes.TANGENTIAL`) whose step
depends on the current state alone: a flow of them rebuilt on a sub-mesh is the same
flow there. DDFV's carried T-vertices keep their barycentric coordinates, which the
rebuilt flow reads from ``T0``."""


def why_not(scheme, integrator=None):
    """Why a run of ``scheme`` cannot go on without a vanished component, or None
    (always None for a ``NAME+STRATEGY``: module docstring).

    Parameters
    ----------
    scheme : mcfbench.running.schemes.Scheme
    integrator : str, optional
        Default the scheme's.

    Returns
    -------
    str or None
    """
    if scheme.mesh_strategy != "none":     # restarted at every change of its mesh
        return None
    integrator = scheme.integrator if integrator is None else integrator
    if scheme.tangential not in STATE_ONLY:
        return (f"{scheme.name}'s tangential strategy {scheme.tangential!r} keeps something "
                "of the initial state, which a flow rebuilt on the remaining components "
                "would not (mcfbench.running.continuation)")
    if INTEGRATORS[integrator].order > 1:
        return (f"the {integrator} integrator's past states are not carried to the "
                "remaining components (mcfbench.running.continuation)")
    if scheme.integrates_itself:
        return (f"{scheme.name} integrates in time itself, from past states that are not "
                "carried to the remaining components (mcfbench.running.continuation)")
    return None


def sub_mesh(faces, keep):
    """The triangles of the vertices ``keep``, renumbered.

    Parameters
    ----------
    faces : (m, 3) int array
    keep : (n,) bool array
        The vertices kept; a triangle is kept when its vertices are.

    Returns
    -------
    faces : (m', 3) int array
        In the kept vertices' numbering (their order kept).
    kept_faces : (m,) bool array
    """
    F = np.asarray(faces)
    kept_faces = keep[F].all(axis=1)
    number = np.cumsum(keep) - 1
    return number[F[kept_faces]], kept_faces


def sub_flow(scheme, flow, keep, *, integrator=None, threads=1, **options):
    """The flow of ``scheme`` on the vertices ``keep`` of ``flow``, at its time level.

    Parameters
    ----------
    scheme : mcfbench.running.schemes.Scheme
    flow : mcfbench.running.flow.SchemeFlow
    keep : (n,) bool array
        The mesh vertices kept (whole components).
    integrator : str, optional
        The run's integrator (default the scheme's).
    threads : int
    **options
        The run's options of the flow class.

    Returns
    -------
    mcfbench.running.flow.SchemeFlow

    Raises
    ------
    ValueError
        The scheme cannot go on this way (:func:`why_not`).
    """
    reason = why_not(scheme, integrator)
    if reason is not None:
        raise ValueError(reason)
    faces, kept_faces = sub_mesh(flow.faces, keep)
    if scheme.extra_points:
        options = {**options, "T0": flow.frame()["extra_points"][kept_faces]}
    new = scheme.make(np.asarray(flow.vertices)[keep], faces, flow.tau, threads=threads,
                      **options)
    new.n = flow.n
    return new


def rebuilt_flow(scheme, flow, vertices, faces, *, threads=1, **options):
    """The flow of ``scheme`` on a new mesh of the surface, at ``flow``'s time level
    (what is carried over: :mod:`mcfbench.running.remeshing`'s docstring; the
    remesh's, a neck cut's and a re-extraction's).

    Parameters
    ----------
    scheme : mcfbench.running.schemes.Scheme
    flow : mcfbench.running.flow.SchemeFlow
    vertices : (n, 3) float array
    faces : (m, 3) int array
    threads : int
    **options
        The run's options of the flow class.
    """
    new = scheme.make(vertices, faces, flow.tau, threads=threads, **options)
    new.n = flow.n
    return new


def exceeded(removed_area_share):
    """Whether a run's surgeries removed more than :data:`MAX_REMOVED_SHARE` of its
    initial area: it does not count as reaching its end."""
    return bool(removed_area_share > MAX_REMOVED_SHARE)
