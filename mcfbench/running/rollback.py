"""Rolling back a step that folds: the ``remesh`` strategy's second chance (issue #44).

A step whose new state has a fold ends a run: the invariants' ``inverted`` (a triangle
turned over that was not at the start or at the last remesh,
:class:`mcfbench.geometry.invariants.FlowInvariants`) or DDFV's ``t_escaped`` (a
T-vertex's projection left its triangle). On a raw mesh the fold is often a neighbour
of a fold the input had and the remesher kept (the scan ``face``: 26 folded edges in
the input, a neighbour flips at step 1-17 in every scheme): the quality trigger
(:class:`mcfbench.geometry.remeshing.RemeshTrigger`) did not fire on the state before
the step, and the step took that state's mesh over the edge. :class:`Rollback` goes
back to the last valid state (the one the step started from, kept before every step),
remeshes it whatever the trigger says (:meth:`mcfbench.running.remeshing.Remesher.remeshed`)
and gives the driver that flow, which redoes the step from it
(:func:`mcfbench.running.driver.simulate`: the failed step's defect and iterations are
forgotten, its state never becomes a frame nor is it observed).

**The cap.** At most :data:`ROLLBACKS` rollbacks in a run, and a second one in a row
to the same time level (the step redone from the remeshed state folded again) only
with progress: its remesh (of the state the last one made) raised the smallest angle
over what the last one left. Remeshing a remeshed state again does improve it, up to
the remesher's own quality: on ``face``, ``ddfv-chord-mdr-carried`` went back to step
15 four times in a row (smallest angle 7.8, 8.5, 14.0, 14.3 degrees after each
remesh) and then reached step 40; a remesh that no longer raises the angle changes
the state by its projection error only, and the step would fold again. Past either
limit, the run ends with the fold's status and message, as without a rollback.
Either way an event of the run: ``{"event": "rolled_back", "step", "time",
"status", "why", "to_step", ...}`` (``step``, ``time`` the failed step's, ``why``
the fold's detail, ``to_step`` the level gone back to, then the fields of
:func:`mcfbench.geometry.remeshing.remesh_change` and the remesh's ``seconds``) or
``{"event": "rollback_refused", "step", "time", "status", "why", "to_step", ...}``
(``why`` saying which limit held, or why the remesh was refused; the remesh's fields
when one was made).

Only a run that stops at a defect rolls back (``on_defect="stop"``, the default): a
run that records its defects goes on past them anyway.
"""

import numpy as np

ROLLBACKS = 10
"""Rollbacks a run may take (module docstring). The prototype on the raw ``face`` took
3 to reach step 40 with ``mdr``; ``ddfv-chord-bgn-carried`` took 11 without
reaching it."""

FOLDS = ("inverted", "t_escaped")
"""The statuses of a fold: the breakdowns a rollback answers."""


class Rollback:
    """The state before each step, and the rollback after a fold.

    Parameters
    ----------
    remesher : mcfbench.running.remeshing.Remesher
        Its :meth:`~mcfbench.running.remeshing.Remesher.remeshed` remeshes the kept
        state and rebuilds the flow there.
    cap : int
        :data:`ROLLBACKS`.

    Attributes
    ----------
    count : int
        Rollbacks taken in the run.
    """

    def __init__(self, remesher, cap=ROLLBACKS):
        self.remesher, self.cap = remesher, cap
        self.count, self.state, self.level, self.angle = 0, None, None, None

    def keep(self, flow):
        """Keep ``flow``'s state, valid, before a step: its mesh (the positions copied;
        the faces do not change within a step) and time level."""
        self.state = (np.array(flow.vertices, dtype=float), np.asarray(flow.faces), flow.n)

    def __call__(self, flow, breakdown):
        """What to do after ``breakdown``, the step from the kept state to ``flow``'s.

        Parameters
        ----------
        flow : mcfbench.running.flow.SchemeFlow
            The state the failed step reached.
        breakdown : mcfbench.running.flow.FlowBreakdown

        Returns
        -------
        None or tuple of (flow or None, dict)
            None for a breakdown that is not a fold (:data:`FOLDS`); else the flow
            rebuilt on the kept state remeshed (at its time level) and the
            ``rolled_back`` event, or None and the ``rollback_refused`` event (module
            docstring).
        """
        if breakdown.status not in FOLDS or self.state is None:
            return None
        V, F, n = self.state
        where = {"step": breakdown.step, "time": breakdown.time,
                 "status": breakdown.status, "to_step": n}
        event, why_not = {}, f"{self.cap} rollbacks in the run already" \
            if self.count >= self.cap else None
        if why_not is None:
            try:
                new, event = self.remesher.remeshed(flow, V, F, n, f"rollback: {breakdown}")
            except ValueError as err:        # the remesher refused the kept state
                why_not = str(err)
        angle = event.get("min_angle_after")
        if why_not is None and n == self.level and not angle > self.angle:
            why_not = (f"the step from step {n} folded again after a rollback to it, and "
                       f"remeshing again did not raise the smallest angle ({angle:.3g} <= "
                       f"{self.angle:.3g} degrees)")
        if why_not is not None:
            return None, {**event, "event": "rollback_refused", **where,
                          "why": f"{breakdown.detail}; not rolled back: {why_not}"}
        self.count, self.level, self.angle = self.count + 1, n, angle
        return new, {**event, "event": "rolled_back", **where, "why": breakdown.detail}
