"""Errors against the shrinking sphere and the experimental order of convergence."""

import numpy as np

_KERNEL = None


def _error_kernel():
    """The compiled pass of :meth:`SphereL2Error.__call__` (numba imported on first use)."""
    global _KERNEL
    if _KERNEL is None:
        import numba

        @numba.njit(cache=True, nogil=True, error_model="numpy")
        def sphere_error_sum(X, c0, c1, c2, r, w):
            """``sum_i w_i (|X_i - c| - r)^2`` in one pass (no temporaries)."""
            total = 0.0
            for i in range(X.shape[1]):
                x0 = X[0, i] - c0
                x1 = X[1, i] - c1
                x2 = X[2, i] - c2
                dist = np.sqrt(x0 * x0 + x1 * x1 + x2 * x2) - r
                total += dist * dist * w[i]
            return total

        _KERNEL = sphere_error_sum
    return _KERNEL


def sphere_radius(t, radius=1.0):
    """Exact radius ``r(t) = sqrt(R^2 - 4 t)`` of a sphere under MCF (Section 3.1)."""
    return np.sqrt(radius**2 - 4.0 * np.asarray(t))


class SphereL2Error:
    """Space-time L2 error (3.2) of a flow started from a sphere.

    Use as an observer of :func:`mcfbench.running.driver.simulate`; the sum runs over the
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
        r = float(sphere_radius(flow.n * flow.tau, self.radius))
        X = np.asarray(flow.X, dtype=np.float64)
        w = np.asarray(flow.l2_weights, dtype=np.float64)
        if X.ndim != 2 or X.shape[0] != 3 or w.shape != (X.shape[1],):
            raise ValueError(f"X must be (3, n) and l2_weights (n,), got {X.shape} and "
                             f"{w.shape}")
        c0, c1, c2 = (float(c) for c in self.centre)
        # (3.2): one compiled pass over the points, no copy of flow.X
        self.total += flow.tau * float(_error_kernel()(X, c0, c1, c2, r, w))
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
