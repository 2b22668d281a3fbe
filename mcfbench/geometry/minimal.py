"""Minimal surfaces spanned by given boundary curves: the Enneper patch.

The journal version of the paper applies the scheme to minimal surfaces
spanned by given curves. A patch whose boundary lies on a known minimal
surface and whose interior is lifted off it relaxes under mean curvature
flow (fixed boundary) to that minimal surface: the exact answer of the
steady state. Enneper's surface (NOTES.md, "More exact answers")::

    x = u - u^3/3 + u v^2,   y = v - v^3/3 + v u^2,   z = u^2 - v^2,

on the parameter disk ``u^2 + v^2 <= R^2``, ``R <= 1`` (there the patch is
stable and the unique minimal surface spanning its boundary), has the area
``(pi/3)((1 + R^2)^3 - 1)``: its area element is ``(1 + u^2 + v^2)^2 du dv``.
"""

import numpy as np

from mcfbench.geometry.shapes import flat_patch


def enneper(u, v):
    """Points of Enneper's surface, ``(m, 3)`` for ``(m,)`` parameters ``u, v``."""
    u, v = np.asarray(u, dtype=float), np.asarray(v, dtype=float)
    return np.column_stack([u - u**3 / 3 + u * v**2, v - v**3 / 3 + v * u**2, u**2 - v**2])


def enneper_area(radius):
    """Area ``(pi/3)((1 + R^2)^3 - 1)`` of the patch over the disk of radius ``R``."""
    return np.pi / 3.0 * ((1.0 + radius**2) ** 3 - 1.0)


def enneper_patch(level=1, radius=0.8, lift=0.2):
    """The Enneper patch over the parameter disk of radius ``R``, its interior
    lifted by ``lift (1 - (u^2 + v^2) / R^2)`` along ``z``.

    The parameter disk is the regular hexagonal Delaunay mesh of
    :func:`mcfbench.geometry.shapes.flat_patch` (``jitter = 0``) scaled by
    ``R``; the boundary circle lies on Enneper's surface and is held fixed.

    Parameters
    ----------
    level : int
        Refinement, ``>= 0`` (each level halves the mesh size; 1: 361 vertices).
    radius : float
        ``R`` in ``(0, 1]``.
    lift : float
        Height of the lifted interior above the minimal surface at the centre.

    Returns
    -------
    vertices : (n, 3) float array
        Interior first, then the boundary circle.
    faces : (m, 3) int64 array
        Normals with a positive ``z`` component (as Enneper's normal for ``R < 1``).
    """
    if not 0 < radius <= 1:
        raise ValueError(f"radius must lie in (0, 1], got {radius!r}")
    disk, F = flat_patch(level, jitter=0.0)
    u, v = radius * disk[:, 0], radius * disk[:, 1]
    V = enneper(u, v)
    V[:, 2] += lift * np.clip(1.0 - (u**2 + v**2) / radius**2, 0.0, None)
    return V, F


def enneper_height_error(vertices, tol=1e-14, iterations=30):
    """Largest vertical distance of ``vertices`` (n, 3) to Enneper's surface.

    Each point's parameters ``(u, v)`` solve ``(x, y)(u, v) = (x_i, y_i)`` by
    Newton's method from ``(x_i, y_i)`` (the map is a perturbation of the
    identity on the disk ``R <= 1``); the distance is ``|z_i - z(u, v)|``.
    """
    P = np.asarray(vertices, dtype=float)
    u, v = P[:, 0].copy(), P[:, 1].copy()
    for _ in range(iterations):
        E = enneper(u, v)
        fx, fy = E[:, 0] - P[:, 0], E[:, 1] - P[:, 1]
        a, b, d = 1.0 - u**2 + v**2, 2.0 * u * v, 1.0 - v**2 + u**2     # Jacobian [[a, b], [b, d]]
        det = a * d - b * b
        du, dv = (d * fx - b * fy) / det, (a * fy - b * fx) / det
        u, v = u - du, v - dv
        if max(np.abs(du).max(), np.abs(dv).max()) < tol:
            break
    return float(np.abs(P[:, 2] - enneper(u, v)[:, 2]).max())
