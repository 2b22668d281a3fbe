"""Quantities of a meridian polygon ``X`` (n, 2) of points ``(r, z)``: what the
axisymmetric reference solver (:mod:`mcfbench.geometry.axisymmetric`) and the
Angenent torus (:mod:`mcfbench.geometry.angenent`) measure of a state.

All from the polygon, all symmetric rules with even error expansions (so that
Richardson extrapolation in the node spacing applies): the area of revolution of
the polygon (frustum sum), the enclosed volume (frustum volumes), the radius of
the middle node (the neck of a mirror-symmetric problem, which stays on
``z = 0``), the largest height, and for a closed meridian the cross-section area.
"""

import math

import numpy as np


def meridian_area(X):
    """Area of the surface of revolution of the polygon, ``sum pi (r_j + r_j+1) |x_j+1 - x_j|``.

    Parameters
    ----------
    X : (n, 2) float array, or (n + 1, 2) with the first node repeated for a closed meridian.

    Returns
    -------
    float
    """
    d = np.diff(X, axis=0)
    return float(np.pi * np.sum((X[1:, 0] + X[:-1, 0]) * np.hypot(d[:, 0], d[:, 1])))


def meridian_volume(X):
    """Volume swept by the polygon: ``|sum pi dz (r_j^2 + r_j r_j+1 + r_j+1^2) / 3|`` (frusta).

    For a meridian from pole to pole, or a closed one (pass it closed), the
    enclosed volume; for an open Dirichlet meridian, the volume between it,
    the axis and the planes of its ends.
    """
    r0, r1, dz = X[:-1, 0], X[1:, 0], np.diff(X[:, 1])
    return float(abs(np.pi * np.sum(dz * (r0 * r0 + r0 * r1 + r1 * r1)) / 3.0))


def cross_section(X):
    """Area enclosed by a closed meridian polygon (shoelace), ``X`` (n, 2) not repeated."""
    r, z = X[:, 0], X[:, 1]
    return float(0.5 * abs(np.sum(r * np.roll(z, -1) - np.roll(r, -1) * z)))


def _closed(X):
    return np.vstack([X, X[:1]])


def meridian_max_height(X, periodic=False):
    """Largest ``z`` of the meridian, by the quartic through the 5 nodes around the
    largest node (interior maximum), or the node itself at the ends."""
    z = X[:, 1]
    n = len(z)
    j = int(np.argmax(z))
    if not periodic and (j < 2 or j > n - 3):
        return float(z[j])
    k = (np.arange(j - 2, j + 3)) % n
    u = np.arange(-2, 3, dtype=float)
    p = np.polynomial.Polynomial.fit(u, z[k], 4, domain=[-2, 2], window=[-2, 2])
    crit = [c.real for c in p.deriv().roots() if abs(c.imag) < 1e-12 and -1.0 <= c.real <= 1.0]
    return float(max([z[j]] + [p(c) for c in crit]))


def measures(X, periodic=False):
    """The reference quantities of one meridian state.

    Returns
    -------
    dict
        ``area``, ``volume``, ``max_height``, ``mid_radius`` (``r`` of the
        middle node, the neck of a mirror-symmetric open meridian with an odd
        number of nodes), ``min_radius`` (smallest nodal ``r`` at an interior
        local minimum of ``r``, nan if none; a check that the neck is the
        middle node);
        for a closed meridian also ``cross_section`` and ``tube_radius``
        ``= sqrt(cross_section / pi)``.
    """
    Y = _closed(X) if periodic else X
    out = {"area": meridian_area(Y), "volume": meridian_volume(Y), "max_height": meridian_max_height(X, periodic)}
    r = X[:, 0]
    inner = (r[1:-1] <= r[:-2]) & (r[1:-1] <= r[2:]) if not periodic else np.zeros(0, bool)
    out["min_radius"] = float(r[1:-1][inner].min()) if inner.any() else float("nan")
    if periodic:
        out["cross_section"] = cross_section(X)
        out["tube_radius"] = math.sqrt(out["cross_section"] / math.pi)
    else:
        out["mid_radius"] = float(r[len(r) // 2])
    return out
