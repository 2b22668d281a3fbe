"""Reference answers of a problem without a closed-form solution, from two
independent schemes on a refinement series.

Used by ``benchmarks/real_mesh_references.py`` for the real-mesh problems
(:mod:`mcfbench.running.real_mesh_problems`); tested on the sphere, whose
answer is known (``tests/mcfbench/running/test_two_scheme_references.py``).

1. :func:`reference_runs`: every scheme on each of its levels ``l`` with
   ``tau_l = tau_0 / 4^(l - l_0)`` to the horizon ``steps tau_0`` (the direct
   solver: a reference must not end on a solver's iteration limit), stopping
   at the first invalid state; the area and the enclosed volume are sampled
   at every checkpoint ``t = j tau_0`` reached.
2. :func:`reference_answers`:

   * **first singularity**: the flow's own singularity (a pinch, a collapse)
     ends every fine enough run at about the same time, whatever the scheme;
     a scheme's breakdown does not. It is taken as found when the two
     finest runs of each scheme all end in a state defect (``inverted``,
     ``degenerated``) at times within a factor :data:`AGREEMENT` of each
     other; its time is the mean of the finest runs' end times. Otherwise
     "none before the horizon", and the runs that stopped are breakdowns.
   * **final time** ``t_final = N tau_0``: the largest ``N`` (at most the
     horizon) before the singularity, and before the first checkpoint whose
     reference area or volume has a relative accuracy worse than
     :data:`ACCURACY`, at which the two finest runs of at least one scheme
     have values (the samples of a run's last state are
     dropped when that state is invalid). A scheme that broke down before
     (e.g. the cotangent scheme, folding on a real mesh while BGN goes on)
     is left out of the checkpoints after its breakdown: the final time is
     the flow's, not the weaker scheme's, so that the matrix can judge that
     breakdown; ``<q>_schemes`` says which schemes each checkpoint's value
     rests on.
   * **reference values** at each checkpoint: per scheme, its finest level,
     Richardson-extrapolated with the order observed on its three finest
     levels when that order lies in ``[0.5, 4]`` (Richardson 1911); its error
     estimate is the extrapolation's correction, or without extrapolation
     the difference of its two finest levels. The reference is the value of
     the scheme with the smaller estimate (the better converged); its
     accuracy is the larger of that estimate and the part of the two
     schemes' difference that the other scheme's own estimate does not
     explain (the schemes agree when ``|A - B| <= e_A + e_B``, a single
     level's estimate counting as 0; both raw numbers are stored too).
   * **orders**: the observed orders of each scheme's levels at its last
     usable checkpoint (``t_final`` unless it broke down;
     :func:`mcfbench.geometry.extrapolation.observed_orders`) and the EOC of
     each scheme's errors against the reference there
     (:func:`mcfbench.geometry.exact.eoc`).
3. :func:`distance_answers`: the reference *surface* at ``t_final`` and the
   accuracy of the distance to it. The reference surface is the finest run
   of the first scheme (in the order of ``levels``: the cotangent scheme
   first) whose two finest runs reach ``t_final``, not extrapolated
   (positions of different meshes do not extrapolate). The length scale is
   ``L = sqrt(A)``, ``A`` the reference area at ``t_final``; the accuracy is
   the larger of ``D / L`` between that run and the scheme's next coarser
   level (a level difference: about 3 times the finest level's own error at
   order 2) and ``D / L`` between it and every other scheme's finest run at
   ``t_final`` (a scheme difference); ``D`` the symmetric mean surface
   distance (:func:`mcfbench.geometry.surface_distance.mean_surface_distance`).
"""

import math

import numpy as np

from mcfbench.geometry import metrics
from mcfbench.geometry.exact import eoc
from mcfbench.geometry.extrapolation import observed_orders
from mcfbench.geometry.surface_distance import mean_surface_distance
from mcfbench.storage.statuses import STATE_STATUSES

AGREEMENT = 1.25
"""Largest ratio of the end times of the finest runs that still counts as one
singularity of the flow."""

ACCURACY = 0.02
"""Largest relative accuracy of a reference value: the final time stops
before the first checkpoint whose area or volume is known less well (on a
coarse real mesh the flow can shrink the surface so fast that the levels part
before the horizon)."""

QUANTITIES = ("area", "volume")


class _Checkpoints:
    """Observer: area, volume and vertex positions at every ``stride``-th time level."""

    def __init__(self, stride):
        self.stride, self.values, self.positions, self.faces = stride, {}, {}, None

    def __call__(self, flow):
        if flow.n % self.stride == 0:
            self.values[flow.n // self.stride] = (metrics.area(flow.vertices, flow.faces),
                                                  metrics.volume(flow.vertices, flow.faces))
            self.positions[flow.n // self.stride] = np.array(flow.vertices, dtype=float)
            self.faces = np.asarray(flow.faces)


def reference_runs(problem, levels, tau_0, steps, solver=None, level_0=None):
    """Run each scheme on its levels and sample the checkpoints.

    Parameters
    ----------
    problem : mcfbench.running.problems.Problem
    levels : dict
        Scheme name -> its levels (coarse to fine), e.g. ``{"cotan": (0, 1, 2),
        "bgn": (0, 1)}``.
    tau_0 : float
        Time step of level ``level_0``; level ``l`` uses ``tau_0 / 4^(l - level_0)``.
    steps : int
        Horizon: ``steps`` checkpoints ``t = j tau_0``, ``j = 1..steps``.
    solver : mcfbench.running.solver.Solver, optional
        Default the direct solver.
    level_0 : int, optional
        Default the smallest level of any scheme.

    Returns
    -------
    list of dict
        Per run: ``scheme``, ``level``, ``vertices``, ``tau``, ``status``,
        ``message``, ``t_end``, ``cpu_seconds``, and ``area``, ``volume``:
        ``steps + 1`` values at ``t = j tau_0`` (``j = 0..steps``; NaN where
        not reached); ``surface``: ``{"faces": (m, 3) int array,
        "positions": {j: (n, 3) float array}}`` at the checkpoints reached
        (in memory only: not JSON).
    """
    from mcfbench.running.run import run
    from mcfbench.running.solver import Solver

    solver = Solver(method="direct") if solver is None else solver
    level_0 = min(min(ls) for ls in levels.values()) if level_0 is None else level_0
    runs = []
    for scheme, scheme_levels in levels.items():
        for level in scheme_levels:
            stride = 4 ** (level - level_0)
            sampler = _Checkpoints(stride)
            result, _ = run(scheme, problem, level, tau=tau_0 / stride, t_final=steps * tau_0,
                            solver=solver, observers=[sampler])
            sampled = [sampler.values.get(j, (math.nan, math.nan)) for j in range(steps + 1)]
            runs.append({"scheme": scheme, "level": int(level), "vertices": result.nV,
                         "tau": result.tau, "status": result.status, "message": result.message,
                         "t_end": result.t_end, "cpu_seconds": result.cpu_seconds,
                         "area": [a for a, _ in sampled], "volume": [v for _, v in sampled],
                         "surface": {"faces": sampler.faces, "positions": sampler.positions}})
    return runs


def _valid_states(run, tau_0):
    """``run`` without the samples of its last state when that state is invalid
    (a run ending in a state defect keeps the invalid state as its last one)."""
    if run["status"] not in STATE_STATUSES:
        return run
    last = run["t_end"] * (1.0 - 1e-9)
    return {**run, **{q: [v if j * tau_0 < last else math.nan for j, v in enumerate(run[q])]
                      for q in QUANTITIES}}


def _by_scheme(runs):
    out = {}
    for r in sorted(runs, key=lambda r: r["level"]):
        out.setdefault(r["scheme"], []).append(r)
    return out


def first_singularity(runs, tau_0, steps):
    """The flow's first singularity from the runs (see the module docstring).

    Returns
    -------
    dict
        ``time`` (``None`` if none was found), ``searched_to`` (the horizon),
        ``decided_by`` (the finest runs' scheme, level, status and end time),
        ``breakdowns`` (runs that stopped before the horizon and are not the
        singularity: scheme, level, status, end time).
    """
    finest = [r for rs in _by_scheme(runs).values() for r in rs[-2:]]
    stops = [r["t_end"] for r in finest]
    found = all(r["status"] in STATE_STATUSES for r in finest) and \
        max(stops) <= AGREEMENT * min(stops)
    time = float(np.mean([rs[-1]["t_end"] for rs in _by_scheme(runs).values()])) if found \
        else None
    stopped = [r for r in runs if r["status"] != "ok"]
    return {"time": time, "searched_to": steps * tau_0,
            "decided_by": [{k: r[k] for k in ("scheme", "level", "status", "t_end")}
                           for r in finest],
            "breakdowns": [] if found else
            [{k: r[k] for k in ("scheme", "level", "status", "t_end")} for r in stopped]}


def scheme_estimate(values):
    """Best value and error estimate of one scheme's levels (coarse to fine).

    Parameters
    ----------
    values : (k,) float array-like
        One quantity on consecutive levels, coarse to fine; non-finite values
        (levels that did not reach the time) are left out.

    Returns
    -------
    value : float
        Richardson-extrapolated from the three finest levels when their observed
        order is in [0.5, 4], else the finest level's (NaN without any).
    accuracy : float
        ``|correction|``, or the two finest levels' difference (NaN for one level).
    method : str
        ``"Richardson, p = ..."``, ``"finest level"``, ``"single level"`` or ``"none"``.
    """
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if len(v) == 0:
        return math.nan, math.nan, "none"
    if len(v) == 1:
        return float(v[-1]), math.nan, "single level"
    if len(v) >= 3:
        p = float(observed_orders(v[-3:])[0])
        if 0.5 <= p <= 4.0:
            correction = (v[-1] - v[-2]) / (2.0 ** p - 1.0)
            return float(v[-1] + correction), float(abs(correction)), f"Richardson, p = {p:.2f}"
    return float(v[-1]), float(abs(v[-1] - v[-2])), "finest level"


def reference_answers(runs, tau_0, steps):
    """Singularity, final time, reference values with accuracy, and orders.

    Parameters
    ----------
    runs : list of dict
        From :func:`reference_runs` (levels one apart, coarse to fine per scheme).
    tau_0 : float
    steps : int
        The horizon of the runs.

    Returns
    -------
    dict
        ``singularity`` (:func:`first_singularity`), ``steps`` (``N``),
        ``checkpoints`` (``1..N``), and per quantity (``area``, ``volume``) the
        reference at the checkpoints, ``<q>_accuracy`` (see the module
        docstring), ``<q>_level_difference`` (the chosen scheme's error
        estimate), ``<q>_scheme_difference`` (``|A - B|``), ``<q>_method``,
        ``<q>_scheme`` (which scheme gave it), ``<q>_schemes`` (the schemes
        compared there), ``<q>_disagree`` (checkpoints where ``|A - B| > e_A
        + e_B``, a single level's ``e`` taken as 0), and ``orders``: per
        scheme and quantity the observed orders and the EOCs against the
        reference at the scheme's last usable checkpoint (``checkpoint``).
    """
    runs = [_valid_states(r, tau_0) for r in runs]
    schemes = _by_scheme(runs)
    singularity = first_singularity(runs, tau_0, steps)
    limit = steps if singularity["time"] is None else \
        min(steps, math.ceil(singularity["time"] / tau_0 - 1e-9) - 1)

    def usable(rs, j):
        """The scheme's two finest runs (its only run) have values at ``j``."""
        return all(np.isfinite(r["area"][j]) for r in rs[-2:])

    N = max((j for j in range(1, limit + 1)
             if any(len(rs) >= 2 and usable(rs, j) for rs in schemes.values())), default=0)
    while True:
        out = _answers_to(N, schemes, usable)
        coarse = [j for j in out["checkpoints"] if any(
            out[f"{q}_accuracy"][j - 1] > ACCURACY * abs(out[q][j - 1]) for q in QUANTITIES)]
        if not coarse:
            return {"singularity": singularity, **out}
        N = coarse[0] - 1


def _answers_to(N, schemes, usable):
    """The answers of :func:`reference_answers` at the checkpoints ``1..N``."""
    out = {"steps": N, "checkpoints": list(range(1, N + 1)),
           "orders": {s: {} for s in schemes}}
    for q in QUANTITIES:
        fields = {k: [] for k in ("", "_level_difference", "_scheme_difference", "_accuracy",
                                  "_method", "_scheme", "_schemes")}
        disagree = []
        for j in range(1, N + 1):
            per = {s: scheme_estimate([r[q][j] for r in rs]) for s, rs in schemes.items()
                   if usable(rs, j)}
            s_best = min(per, key=lambda s: per[s][1] if np.isfinite(per[s][1]) else math.inf)
            others = [s for s in per if s != s_best]
            difference = max((abs(per[s][0] - per[s_best][0]) for s in others), default=math.nan)
            unexplained = max((abs(per[s][0] - per[s_best][0]) - np.nan_to_num(per[s][1])
                               for s in others), default=0.0)
            for key, value in (("", per[s_best][0]), ("_level_difference", per[s_best][1]),
                               ("_scheme_difference", float(difference)),
                               ("_accuracy", float(max(per[s_best][1], unexplained))),
                               ("_method", per[s_best][2]), ("_scheme", s_best),
                               ("_schemes", sorted(per))):
                fields[key].append(value)
            if unexplained > np.nan_to_num(per[s_best][1]):
                disagree.append(j)
        out.update({f"{q}{key}": values for key, values in fields.items()})
        out[f"{q}_disagree"] = disagree
        for s, rs in schemes.items():
            last = max((j for j in range(1, N + 1) if usable(rs, j)), default=0)
            final = [r[q][last] for r in rs]
            reference = out[q][last - 1] if last else math.nan
            out["orders"][s][q] = {
                "checkpoint": last, "levels": [r["level"] for r in rs],
                "observed": [float(x) for x in observed_orders(final)] if len(rs) >= 3 else [],
                "eoc_against_reference": [float(x) for x in eoc(np.asarray(final) - reference)[1:]]}
    return out


def distance_answers(runs, answers, tau_0):
    """The reference surface at ``t_final`` and the accuracy of the distance to
    it (module docstring, item 3).

    Parameters
    ----------
    runs : list of dict
        From :func:`reference_runs` (each with its ``surface``), scheme by
        scheme in the order of preference.
    answers : dict
        :func:`reference_answers` of these runs (``steps`` ``N >= 1``, ``area``).
    tau_0 : float

    Returns
    -------
    answers : dict
        ``length_scale`` (``L``), ``distance_reference`` (``scheme``,
        ``level``, ``checkpoint`` ``N``, ``vertices``), ``distance_level_difference``
        and ``distance_scheme_difference`` (``D / L``; the latter NaN when no
        other scheme reaches ``t_final``), ``distance_accuracy`` (their larger).
    surface : ((n, 3) float array, (m, 3) int array)
        The reference run's vertex positions at ``t_final`` and its faces.

    Raises
    ------
    ValueError
        No checkpoint (``N = 0``), or no scheme whose two finest runs reach it.
    """
    N = answers["steps"]
    if N < 1:
        raise ValueError("no checkpoint (N = 0): no reference surface")
    schemes = _by_scheme([_valid_states(r, tau_0) for r in runs])
    chosen = [s for s, rs in schemes.items()
              if len(rs) >= 2 and all(np.isfinite(r["area"][N]) for r in rs[-2:])]
    if not chosen:
        raise ValueError(f"no scheme's two finest runs reach t_final = {N} tau_0")
    scheme, length = chosen[0], math.sqrt(answers["area"][N - 1])

    def surface(run):
        return run["surface"]["positions"][N], run["surface"]["faces"]

    finest = surface(schemes[scheme][-1])
    level = mean_surface_distance(*finest, *surface(schemes[scheme][-2])) / length
    others = [[r for r in rs if np.isfinite(r["area"][N])] for s, rs in schemes.items()
              if s != scheme]
    between = max((mean_surface_distance(*finest, *surface(rs[-1])) / length
                   for rs in others if rs), default=math.nan)
    return ({"length_scale": length,
             "distance_reference": {"scheme": scheme, "level": schemes[scheme][-1]["level"],
                                    "checkpoint": N, "vertices": len(finest[0])},
             "distance_level_difference": level, "distance_scheme_difference": between,
             "distance_accuracy": float(np.nanmax([level, between]))}, finest)
