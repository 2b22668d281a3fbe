"""Errors against the shrinking sphere and the experimental order of convergence."""

import math

import numpy as np

from mcfbench.geometry.metrics import catenoid_parameter


def sphere_radius(t, radius=1.0):
    """Exact radius ``r(t) = sqrt(R^2 - 4 t)`` of a sphere under MCF (Section 3.1)."""
    return np.sqrt(radius**2 - 4.0 * np.asarray(t))


def sphere_state_errors(vertices, weights, t, *, normals=None, curvature=None, radius=1.0):
    """Errors at time ``t`` of a state of the flow of the sphere of radius ``R`` about the
    origin: position, normal and mean curvature, lumped L2.

    ``sqrt(sum_i w_i e_i^2)`` with ``e_i`` the distance ``| |x_i| - r(t) |`` to the exact
    sphere (:func:`sphere_radius`), ``|nu_i - x_i / |x_i||`` (the outer unit normal at the
    point's direction) and ``|H_i - 2 / r(t)|`` (``H = div nu``: positive on a sphere
    with its outer normal).

    Parameters
    ----------
    vertices : (n, 3) float array
    weights : (n,) float array
        Quadrature weights (a lumped mass).
    t : float
    normals : (n, 3) float array, optional
    curvature : (n,) float array, optional
    radius : float

    Returns
    -------
    dict
        ``"position"``, and ``"normal"``, ``"curvature"`` when given.

    Examples
    --------
    >>> X = np.array([[0.5, 0, 0], [0, 0, -0.5]])
    >>> e = sphere_state_errors(X, [1.0, 1.0], 0.1875, normals=-X, curvature=[4.0, 3.0])
    >>> {k: round(float(v), 6) for k, v in e.items()}
    {'position': 0.0, 'normal': 2.12132, 'curvature': 1.0}
    """
    X, w = np.asarray(vertices, dtype=float), np.asarray(weights, dtype=float)
    r = float(sphere_radius(t, radius))
    distance = np.linalg.norm(X, axis=1)
    errors = {"position": np.sqrt(w @ (distance - r) ** 2)}
    if normals is not None:
        exact = X / distance[:, None]
        errors["normal"] = np.sqrt(w @ ((np.asarray(normals) - exact) ** 2).sum(axis=1))
    if curvature is not None:
        errors["curvature"] = np.sqrt(w @ (np.asarray(curvature) - 2.0 / r) ** 2)
    return {key: float(value) for key, value in errors.items()}


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
        with np.errstate(invalid="ignore"):     # past R^2 / 4 (a run to the extinction,
            r = float(sphere_radius(flow.n * flow.tau, self.radius))   # NaN: no error)
        X = np.asarray(flow.X, dtype=np.float64)
        w = np.asarray(flow.l2_weights, dtype=np.float64)
        if X.ndim != 2 or X.shape[0] != 3 or w.shape != (X.shape[1],):
            raise ValueError(f"X must be (3, n) and l2_weights (n,), got {X.shape} and "
                             f"{w.shape}")
        c0, c1, c2 = (float(c) for c in self.centre)
        # (3.2): one compiled pass over the points, no copy of flow.X
        from mcfbench.geometry.kernels import sphere_error_sum  # numba on first use

        self.total += flow.tau * float(sphere_error_sum(X, c0, c1, c2, r, w))
        self.levels += 1

    @property
    def value(self):
        """The L2 error of the levels observed so far."""
        return float(np.sqrt(self.total))


def eoc(errors, levels=None, ok=None, sizes=None):
    """Experimental order of convergence (3.1): the one EOC of the suite.

    ``log(|e_{j-1}| / |e_j|) / log(s_{j-1} / s_j)`` between successive rows,
    ``s`` the mesh size (halved per level: ``log 2``) or the time step.

    Parameters
    ----------
    errors : (k,) array_like
        Errors, rows ordered from coarse to fine.
    levels : (k,) int array_like, optional
        Refinement levels of the rows: an order is taken only between rows one
        level apart (default: every pair of successive rows).
    ok : (k,) bool array_like, optional
        Rows whose run finished; no order is taken against any other.
    sizes : (k,) array_like, optional
        Mesh sizes or time steps of the rows (default: halved per row).

    Returns
    -------
    (k,) float array
        The order of each row against the previous one; NaN for the first
        row, next to a row that is not ok, between rows that are not one
        level apart, and where an error is zero or not finite.

    Examples
    --------
    >>> eoc([1e-2, 2.5e-3]).round(3).tolist()
    [nan, 2.0]
    >>> eoc([1e-2, 2.5e-3, float("nan"), 4e-4], levels=[1, 2, 3, 4]).round(3).tolist()
    [nan, 2.0, nan, nan]
    """
    e = np.abs(np.asarray(errors, dtype=float))
    valid = np.isfinite(e) & (e > 0)
    if ok is not None:
        valid &= np.asarray(ok, dtype=bool)
    pair = np.r_[False, valid[1:] & valid[:-1]]
    if levels is not None:
        pair &= np.r_[False, np.diff(np.asarray(levels)) == 1]
    with np.errstate(divide="ignore", invalid="ignore"):
        if sizes is None:
            order = np.r_[np.nan, np.log2(e[:-1] / e[1:])]
        else:
            s = np.asarray(sizes, dtype=float)
            order = np.r_[np.nan, np.log(e[:-1] / e[1:]) / np.log(s[:-1] / s[1:])]
    return np.where(pair, order, np.nan)


J01_SQUARED = 5.783185962946784
"""Square of the first zero of the Bessel function ``J_0`` (NOTES.md)."""


def disk_decay_rate(radius=1.0):
    """Rate ``lambda = j_{0,1}^2 / R^2`` at which a surface spanning a circle of
    radius ``R`` relaxes to the flat disk: near it the height solves the heat
    equation with Dirichlet data, ``z ~ exp(-lambda t) J_0(j_{0,1} r / R)``
    (NOTES.md, "More exact answers")."""
    return J01_SQUARED / radius**2


def catenoid_area(radius=1.0, half_height=0.5):
    """Area ``pi a (2 h + a sinh(2 h / a))`` of the stable catenoid (NOTES.md)."""
    a = catenoid_parameter(radius, half_height)
    return math.pi * a * (2.0 * half_height + a * math.sinh(2.0 * half_height / a))
