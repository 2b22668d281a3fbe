"""The axisymmetric flow continued through a neck pinch: the meridian cut at its neck,
each part closed at the axis, flowed on to its own extinction.

A rotationally symmetric neck pinch of a graph-like profile (the dumbbell) is
followed by two smooth parts that shrink on their own: the level-set flow goes
through it without fattening and the parts become smooth again at once
(Altschuler, Angenent and Giga, J. Geom. Anal. 5 (1995) 293-358). The meridian
solver (:mod:`mcfbench.geometry.axisymmetric`) cannot reach ``r = 0`` at an
interior node, so the continuation is a surgery at a small neck radius
``delta``:

1. flow the whole meridian until the neck (the middle node of a
   mirror-symmetric meridian, on ``z = 0``) has radius ``delta``
   (:func:`mcfbench.geometry.axisymmetric.evolve_until`);
2. keep the upper half (top pole to the neck) and close it at the axis by a
   quarter circle of radius ``delta`` centred on the axis at the neck's height
   (:func:`capped_bulb`): the neck's tangent is vertical (``r`` is smallest
   there), so the cap joins it with a continuous tangent and meets the axis
   at a right angle, as an ``"axis"`` end of the solver requires; by symmetry
   the lower half is its mirror image;
3. flow the capped part on, ``ends = ("axis", "axis")``, until it vanishes
   (:func:`bulb_through_pinch`); its extinction time comes from the approach of
   its area radius ``rho = sqrt(A / (4 pi))`` to zero
   (:func:`mcfbench.geometry.extrapolation.extinction_time`).

The cap changes the profile by ``O(delta)`` over a length ``O(delta)``: the
volume it adds is ``(2/3) pi delta^3`` and the flow smooths the joint within a
time ``O(delta^2)``. Its effect on what follows is measured by repeating the
surgery at ``delta, delta/2, delta/4`` (:mod:`mcfbench.geometry.axisymmetric_references`,
problem ``dumbbell_after_pinch``), not assumed.
"""

import math

import numpy as np

from mcfbench.geometry.axisymmetric import evolve_until, initial_meridian
from mcfbench.geometry.meridians import meridian_area, meridian_volume


def capped_bulb(X, spacing=None):
    """The upper part of a mirror-symmetric meridian cut at its neck and closed at the axis.

    Parameters
    ----------
    X : (n, 2) float array
        A pole-to-pole meridian ``(r, z)`` from the top pole (``X[0]``) to the
        bottom one, ``n`` odd, its middle node the neck on ``z = 0``.
    spacing : float, optional
        Arc length between the new nodes (default: the mean spacing of the
        upper half of ``X``).

    Returns
    -------
    (m, 2) float array
        From the top pole to the cap's pole ``(0, z_neck - r_neck)``, nodes equally
        spaced in arc length along the upper half (a cubic spline through its
        nodes in chord length) followed by the quarter circle of radius
        ``r_neck`` centred at ``(0, z_neck)``. Both ends lie on the axis.

    Raises
    ------
    ValueError
        ``n`` even, or the middle node is not a local minimum of ``r`` (not a neck).
    """
    from scipy.interpolate import CubicSpline

    X = np.asarray(X, dtype=float)
    n = len(X)
    if n % 2 == 0 or n < 5:
        raise ValueError(f"a mirror-symmetric meridian with a middle node needs an odd "
                         f"number of nodes >= 5, got {n}")
    k = n // 2
    r_neck, z_neck = X[k]
    if not (X[k - 1, 0] >= r_neck <= X[k + 1, 0]) or r_neck <= 0.0:
        raise ValueError(f"the middle node (r = {r_neck:.3g}) is not a neck: r is not "
                         f"smallest there")
    upper = X[: k + 1]
    chord = np.r_[0.0, np.cumsum(np.hypot(*np.diff(upper, axis=0).T))]
    spline = CubicSpline(chord, upper, axis=0)
    cap = 0.5 * math.pi * r_neck
    total = chord[-1] + cap
    if spacing is None:
        spacing = chord[-1] / k
    m = max(int(round(total / spacing)) + 1, 5)
    s = total * np.arange(m) / (m - 1)
    out = np.empty((m, 2))
    on_upper = s <= chord[-1]
    out[on_upper] = spline(s[on_upper])
    theta = (s[~on_upper] - chord[-1]) / r_neck
    out[~on_upper] = np.column_stack([r_neck * np.cos(theta), z_neck - r_neck * np.sin(theta)])
    out[0] = (0.0, upper[0, 1])
    out[-1] = (0.0, z_neck - r_neck)
    return out


def area_radius(X):
    """``sqrt(A / (4 pi))`` of a pole-to-pole meridian, ``A`` its area of revolution: the
    radius of the sphere of the same area, which falls to 0 at the extinction."""
    return math.sqrt(meridian_area(X) / (4.0 * math.pi))


def _mid(X):
    return float(X[len(X) // 2, 0])


def bulb_through_pinch(n, delta, times, rho_levels, rtol=1e-11):
    """The dumbbell (``initial_meridian("dumbbell", n)``) flowed to a neck of radius
    ``delta``, cut there (:func:`capped_bulb`) and its upper bulb flowed on until its
    area radius has fallen through ``rho_levels``.

    Parameters
    ----------
    n : int
        Nodes of the dumbbell's meridian (odd); the bulb keeps its spacing.
    delta : float
        The neck radius at the cut.
    times : sequence of float
        Increasing times after the cut at which the bulb's measures are returned.
    rho_levels : sequence of float
        Decreasing area radii whose times are found (the extinction's approach).
    rtol : float
        Radau's tolerances (relative and absolute).

    Returns
    -------
    dict
        ``t_cut`` (the time the neck reached ``delta``), ``volume``, ``area`` (of
        one bulb at ``times``), ``t_levels`` (times at which its area radius reached
        ``rho_levels``), ``bulb_nodes`` (its node count).

    Raises
    ------
    ValueError
        A time of ``times`` before the cut.
    """
    X, ends, periodic = initial_meridian("dumbbell", n)
    (t_cut,), _, X_cut = evolve_until(X, _mid, [delta], ends, periodic, rtol=rtol, atol=rtol)
    early = [t for t in times if t <= t_cut]
    if early:
        raise ValueError(f"times {early} are not after the cut at t = {t_cut:.6g}")
    bulb = capped_bulb(X_cut)
    t_levels, _, _, recorded = evolve_until(
        bulb, area_radius, rho_levels, ("axis", "axis"), False, rtol=rtol, atol=rtol,
        record_times=[t - t_cut for t in times])
    return {"t_cut": float(t_cut),
            "volume": [meridian_volume(Y) for Y in recorded],
            "area": [meridian_area(Y) for Y in recorded],
            "t_levels": t_cut + np.asarray(t_levels),
            "bulb_nodes": len(bulb)}
