"""Reference numbers of the rotationally symmetric problems from the meridian solver (:mod:`mcfbench.geometry.axisymmetric`) on fine meshes with Richardson extrapolation: the torus and dumbbell pinch times, volume, area and radius at fixed times, the catenoid's approach, the hemisphere's decay rate (against j_{0,1}^2 / R^2) and the pinch of a long cylinder, each with an error estimate."""

import math

import numpy as np
from scipy.optimize import brentq

from mcfbench.geometry.axisymmetric import evolve, evolve_until, initial_meridian
from mcfbench.geometry.meridians import cross_section, measures
from mcfbench.geometry.exact import J01_SQUARED, catenoid_area
from mcfbench.geometry.extrapolation import (
    extinction_time,
    pinch_time_neck,
    pinch_time_tube,
    richardson,
)
from mcfbench.geometry.metrics import catenoid_parameter


def critical_aspect_ratio():
    """Largest ``h / R`` for which a catenoid spans circles of radius ``R`` at ``z = +-h``.

    ``h / R = x / cosh x`` at the root of ``x tanh x = 1`` (the fold of the
    catenoid family); 0.662743... Beyond it a cylinder between the circles
    pinches.
    """
    x = brentq(lambda x: x * math.tanh(x) - 1.0, 0.5, 2.0, xtol=1e-15)
    return x / math.cosh(x)


def _extrapolate(per_mesh, coarse_tight=None, coarse=None):
    """Richardson over meshes of each quantity; the time-tolerance effect (the
    coarsest mesh run with tolerances 10x tighter) is added to the error, which
    is floored at ``1e-14 |value|`` (rounding)."""
    out = {}
    for key in per_mesh[0]:
        vals = np.array([m[key] for m in per_mesh], dtype=float)
        if vals.ndim == 1:
            v, e, _ = richardson(vals)
            if coarse_tight is not None:
                e += abs(coarse_tight[key] - coarse[key])
            out[key] = (v, max(e, 1e-14 * abs(v)))  # floor: rounding of the sums
        else:
            rows = [richardson(vals[:, k]) for k in range(vals.shape[1])]
            err = np.array([r[1] for r in rows])
            if coarse_tight is not None:
                err = err + np.abs(np.asarray(coarse_tight[key]) - np.asarray(coarse[key]))
            value = np.array([r[0] for r in rows])
            out[key] = (value, np.maximum(err, 1e-14 * np.abs(value)))
    return out


def _fixed_time_run(shape, n, times, params, rtol, atol_factor=1.0):
    X, ends, per = initial_meridian(shape, n, **params)
    states = evolve(X, times, ends, per, rtol=rtol, atol=rtol * atol_factor)
    ms = [measures(Y, per) for Y in states]
    return {k: [m[k] for m in ms] for k in ms[0]}


def _pinch_run(shape, n, levels, times, params, rtol, quantity):
    X, ends, per = initial_meridian(shape, n, **params)
    t_lev, _, X_last, rec = evolve_until(X, quantity, levels, ends, per, rtol=rtol, atol=rtol,
                                         record_times=times)
    ms = [measures(Y, per) for Y in rec]
    out = {k: [m[k] for m in ms] for k in ms[0]}
    out["t_levels"] = t_lev
    last = measures(X_last, per)
    out["max_height_at_last_level"] = last["max_height"]
    return out


def _bulb_run(n, delta, times, rho_levels, rtol):
    from mcfbench.geometry.meridian_surgery import bulb_through_pinch

    run = bulb_through_pinch(n, delta, times, rho_levels, rtol)
    T, _ = extinction_time(run["t_levels"], rho_levels)
    return {"bulb_volume": run["volume"], "bulb_area": run["area"], "extinction_time": T,
            "t_cut": run["t_cut"]}


def _series_run(run, ns, *args, rtol=1e-11):
    per_mesh = [run(n, *args, rtol) for n in ns]
    coarse_tight = run(ns[0], *args, rtol / 10)
    return _extrapolate(per_mesh, coarse_tight, per_mesh[0]), per_mesh


def _mid(X):
    return float(X[len(X) // 2, 0])


def _tube(X):
    return math.sqrt(cross_section(X) / math.pi)


def reference_numbers(problems=("torus", "dumbbell", "dumbbell_after_pinch", "catenoid",
                                "hemisphere", "long_cylinder"), quick=False):
    """Reference answers for the suite's axisymmetric problems (computed, nothing cached).

    Every number is ``(value, error_estimate)``: Richardson extrapolation over
    meshes ``n, 2n, 4n, 8n`` (orders 2, 4, 4, 6 of :func:`richardson`; error =
    difference to the next-lower column) plus the change when the coarsest mesh is rerun with
    time tolerances ten times tighter; pinch times add the spread of the
    asymptotic fits (:func:`pinch_time_tube`, :func:`pinch_time_neck`).

    Problems (initial shapes of ``mcfbench.running.problems``):

    * ``torus``: ``R = 2, r = 0.5``; ``volume``, ``area``, ``tube_radius``
      (``sqrt(cross-section / pi)``), ``max_height`` at ``times``; ``pinch_time``
      (the tube shrinks to a circle of radius ``ring_radius``).
    * ``dumbbell``: ``volume``, ``area``, ``mid_radius`` (the neck on
      ``z = 0``), ``max_height`` at ``times``; ``pinch_time``.
    * ``dumbbell_after_pinch``: the dumbbell continued through its pinch
      (:mod:`mcfbench.geometry.meridian_surgery`: cut at the neck radius ``delta``,
      each bulb closed at the axis and flowed to its extinction), for each cut
      radius of ``deltas``: ``bulb_volume`` and ``bulb_area`` (one bulb; the two
      are mirror images) at ``times`` and the bulbs' ``extinction_time``
      (:func:`extinction_time`); the entries without a suffix are those of the
      smallest ``delta`` with the change from the next larger one added to their
      error (``delta_effect``: that change, per quantity).
    * ``catenoid``: cylinder ``R = 1, h = 0.5`` between fixed circles:
      ``mid_radius`` (neck) and ``area`` at ``times``, the last one (t = 8) at
      the steady state, with the exact catenoid ``a``, its area.
    * ``hemisphere``: ``R = 1``, equator fixed: ``max_height`` at ``times``;
      ``decay_rate = log(z(1.5) / z(2)) / 0.5`` and ``decay_rate_late`` (from
      ``t = 2`` to 2.5) against ``j01^2 / R^2`` (they differ from it by the
      nonlinear ``O(z^2)`` correction, 3e-8 and 1e-10).
    * ``long_cylinder``: ``R = 1, h = 1`` (``h / R`` beyond
      :func:`critical_aspect_ratio`): neck at ``times`` and ``pinch_time``.

    Parameters
    ----------
    problems : sequence of str
    quick : bool
        Coarser meshes (a smoke test: about 10 s, errors far larger).

    Returns
    -------
    dict
        ``problem -> {quantity: (value, error)}`` (arrays over ``times`` for
        time series) plus ``times`` and setting entries.
    """
    out = {}
    neck_levels = 0.1 * 2.0 ** (-0.5 * np.arange(10 if not quick else 6))
    if "torus" in problems:
        ns = (128, 256, 512, 1024) if not quick else (32, 64, 128)
        levels = 0.1 * 2.0 ** (-0.5 * np.arange(9))
        times = (0.025, 0.05, 0.075, 0.1)
        ex, _ = _series_run(lambda n, rtol: _pinch_run(
            "torus", n, levels, times, {"R": 2.0, "r": 0.5}, rtol, _tube), ns)
        T, eT = pinch_time_tube(ex["t_levels"][0], levels)
        res = {k: ex[k] for k in ("volume", "area", "tube_radius", "max_height")}
        res.update(times=times, meshes=ns, levels=levels, t_levels=ex["t_levels"],
                   pinch_time=(T, eT + float(ex["t_levels"][1].max())))
        out["torus"] = res
    if "dumbbell" in problems:
        ns = (1601, 3201, 6401, 12801) if not quick else (201, 401, 801)
        times = (0.02, 0.04, 0.06, 0.08)
        ex, _ = _series_run(lambda n, rtol: _pinch_run(
            "dumbbell", n, neck_levels, times, {}, rtol, _mid), ns)
        T, eT, _fits = pinch_time_neck(ex["t_levels"][0], neck_levels,
                                       last=(4, 5, 6) if not quick else (3, 4, 5))
        res = {k: ex[k] for k in ("volume", "area", "mid_radius", "max_height")}
        res.update(times=times, meshes=ns, levels=neck_levels, t_levels=ex["t_levels"],
                   max_height_at_last_level=ex["max_height_at_last_level"],
                   pinch_time=(T, eT + float(ex["t_levels"][1].max())))
        out["dumbbell"] = res
    if "dumbbell_after_pinch" in problems:
        ns = (1601, 3201, 6401, 12801) if not quick else (201, 401, 801)
        deltas = (0.01, 0.005, 0.0025) if not quick else (0.04, 0.02, 0.01)
        times = (0.12, 0.16, 0.2)
        rho_levels = 0.2 * 2.0 ** (-0.5 * np.arange(9))
        by_delta = {delta: _series_run(lambda n, rtol, d=delta: _bulb_run(
            n, d, times, rho_levels, rtol), ns)[0] for delta in deltas}
        finest, coarser = by_delta[deltas[-1]], by_delta[deltas[-2]]
        keys = ("bulb_volume", "bulb_area", "extinction_time")
        effect = {k: np.abs(np.asarray(finest[k][0]) - np.asarray(coarser[k][0])) for k in keys}
        res = {k: (finest[k][0], finest[k][1] + effect[k]) for k in keys}
        res.update(times=times, meshes=ns, deltas=deltas, rho_levels=rho_levels,
                   by_delta=by_delta, delta_effect=effect)
        out["dumbbell_after_pinch"] = res
    if "catenoid" in problems:
        ns = (33, 65, 129, 257, 513) if not quick else (17, 33, 65)
        times = (0.1, 0.25, 0.5, 1.0, 1.5, 8.0)
        ex, _ = _series_run(lambda n, rtol: _fixed_time_run(
            "cylinder", n, times, {"radius": 1.0, "half_height": 0.5}, rtol), ns)
        out["catenoid"] = {"mid_radius": ex["mid_radius"], "area": ex["area"],
                           "volume": ex["volume"], "times": times, "meshes": ns,
                           "exact_neck": catenoid_parameter(1.0, 0.5),
                           "exact_area": catenoid_area(1.0, 0.5)}
    if "hemisphere" in problems:
        ns = (33, 65, 129, 257, 513) if not quick else (17, 33, 65)
        times = (0.1, 0.25, 0.5, 1.0, 1.5, 2.0, 2.5)

        def run(n, rtol):  # heights down to 1e-6: absolute tolerance 1e-5 rtol
            r = _fixed_time_run("hemisphere", n, times, {"radius": 1.0}, rtol, 1e-5)
            z = r["max_height"]
            r["decay_rate"] = math.log(z[4] / z[5]) / 0.5
            r["decay_rate_late"] = math.log(z[5] / z[6]) / 0.5
            return r

        ex, _ = _series_run(run, ns)
        out["hemisphere"] = {"max_height": ex["max_height"], "area": ex["area"],
                             "volume": ex["volume"], "decay_rate": ex["decay_rate"],
                             "decay_rate_late": ex["decay_rate_late"], "times": times,
                             "meshes": ns, "exact_rate": J01_SQUARED}
    if "long_cylinder" in problems:
        ns = (801, 1601, 3201, 6401) if not quick else (101, 201, 401)
        times = (0.05, 0.1, 0.15)
        ex, _ = _series_run(lambda n, rtol: _pinch_run(
            "cylinder", n, neck_levels, times, {"radius": 1.0, "half_height": 1.0}, rtol, _mid), ns)
        T, eT, _fits = pinch_time_neck(ex["t_levels"][0], neck_levels,
                                       last=(4, 5, 6) if not quick else (3, 4, 5))
        out["long_cylinder"] = {"radius": 1.0, "half_height": 1.0,
                                "critical_ratio": critical_aspect_ratio(),
                                "mid_radius": ex["mid_radius"], "area": ex["area"],
                                "times": times, "meshes": ns, "levels": neck_levels,
                                "t_levels": ex["t_levels"],
                                "pinch_time": (T, eT + float(ex["t_levels"][1].max()))}
    return out


def format_reference_table(ref):
    """Plain-text table of :func:`reference_numbers` (value and error estimate per row).

    Returns
    -------
    str
    """
    lines = [f"{'problem':<14}{'quantity':<26}{'t':>8}  {'value':>22}  {'error est.':>10}"]
    for prob, res in ref.items():
        times = res.get("times", ())
        for key, item in res.items():
            if not (isinstance(item, tuple) and len(item) == 2) or key == "times":
                continue
            value, err = item
            if np.ndim(value) == 1 and len(value) == len(times):
                for t, v, e in zip(times, value, err):
                    lines.append(f"{prob:<14}{key:<26}{t:>8g}  {v:>22.15g}  {e:>10.1e}")
            elif np.ndim(value) == 0:
                lines.append(f"{prob:<14}{key:<26}{'':>8}  {float(value):>22.15g}  {float(err):>10.1e}")
        for key in ("exact_neck", "exact_area", "exact_rate", "critical_ratio"):
            if key in res:
                lines.append(f"{prob:<14}{key:<26}{'':>8}  {res[key]:>22.15g}  {'exact':>10}")
    return "\n".join(lines)


def format_cut_table(result):
    """Plain-text table of the dumbbell continued through its pinch
    (:func:`reference_numbers`' ``dumbbell_after_pinch``): every quantity at each cut
    radius ``delta`` with its error estimate over meshes, and the change from the
    next larger ``delta`` (the cut's effect, to be compared with the error).

    Returns
    -------
    str
    """
    lines = [f"{'quantity':<18}{'t':>6}{'delta':>9}  {'value':>20}  {'error est.':>10}  "
             f"{'change from 2 delta':>20}"]
    deltas, times = result["deltas"], result["times"]
    rows = [("extinction_time", None)] + [(k, i) for k in ("bulb_volume", "bulb_area")
                                           for i in range(len(times))]
    for key, i in rows:
        previous = None
        for delta in deltas:
            value, err = result["by_delta"][delta][key]
            value, err = (value, err) if i is None else (value[i], err[i])
            change = "" if previous is None else f"{value - previous:>20.2e}"
            t = "" if i is None else f"{times[i]:g}"
            lines.append(f"{key:<18}{t:>6}{delta:>9g}  {value:>20.12g}  {err:>10.1e}  {change}")
            previous = value
    return "\n".join(lines)

