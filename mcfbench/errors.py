"""Errors against the shrinking sphere and the experimental order of convergence."""

import numpy as np


def sphere_radius(t, radius=1.0):
    """Exact radius ``r(t) = sqrt(R^2 - 4 t)`` of a sphere under MCF (Section 3.1)."""
    return np.sqrt(radius**2 - 4.0 * np.asarray(t))


class SphereL2Error:
    """Space-time L2 error (3.2) of a flow started from a sphere.

    Use as an observer of :func:`mcfbench.driver.simulate`; the sum runs over the
    time levels ``n = 1 ... N`` and the points of ``flow.X`` with the
    weights ``flow.l2_weights`` of level ``n``: for DDFV the covolume
    areas ``chi^n / 2`` of F- and T-vertices (each family tiles the surface
    once), for the cotangent baseline the lumped mass of the vertices.

    Parameters
    ----------
    radius : float
        Initial radius ``R``.
    centre : (3,) float array
        Centre of the sphere.
    """

    def __init__(self, radius=1.0, centre=(0.0, 0.0, 0.0)):
        self.radius = float(radius)
        self.centre = np.asarray(centre, dtype=float)
        self.total = 0.0
        self.levels = 0

    def __call__(self, flow):
        if flow.n == 0:
            return
        r = sphere_radius(flow.n * flow.tau, self.radius)
        X = flow.X - self.centre[:, None]
        dist = np.sqrt(X[0] ** 2 + X[1] ** 2 + X[2] ** 2) - r
        self.total += flow.tau * float(np.dot(dist**2, flow.l2_weights))  # (3.2)
        self.levels += 1

    @property
    def value(self):
        """The L2 error of the levels observed so far."""
        return float(np.sqrt(self.total))


def eoc(errors):
    """Experimental order of convergence (3.1) between successive halvings of h.

    Parameters
    ----------
    errors : (k,) array_like
        Errors on meshes of edge length ``h, h/2, h/4, ...``.

    Returns
    -------
    (k,) float array
        ``log2(e_{j-1} / e_j)``; the first entry is NaN.

    Examples
    --------
    >>> eoc([1e-2, 2.5e-3]).round(3).tolist()
    [nan, 2.0]
    """
    e = np.asarray(errors, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.r_[np.nan, np.log2(e[:-1] / e[1:])]
