"""The time integrators, one for every scheme: semi-implicit Euler and linearly implicit BDF2.

A scheme provides its spatial operators at a state (:meth:`Flow.system
<mcfbench.running.flow.Flow.system>`): the linear system of

    M(X*) (X^{n+1} - B) / dt + L(X*) X^{n+1} = g(X*)                        (I1)

for an evaluation state ``X*``, a base state ``B`` and a step ``dt`` (``M``
its mass-like operator, ``L`` its stiffness, ``g`` what it adds
explicitly, e.g. the elimination (3.6) or a tangential velocity, each
assembled at ``X*``). An integrator chooses the three:

``euler`` (:class:`Euler`, the paper's semi-implicit step (2.1), the default)
    ``X* = B = X^n``, ``dt = tau``: first order.
``bdf2`` (:class:`BDF2`, linearly implicit BDF2 with the operators at the
extrapolated state, Kovacs, Li, Lubich, Numer. Math. 143 (2019), (4.2) with
``k = 2``)
    ``(3 X^{n+1} - 4 X^n + X^{n-1}) / (2 tau)`` on the left: multiplying by
    ``2 tau / 3`` gives (I1) with::

        X* = 2 X^n - X^{n-1},  B = (4 X^n - X^{n-1}) / 3,  dt = 2 tau / 3    (I2)

    The first step is an Euler step: its local error is O(tau^2), so the
    global error stays O(tau^2) (measured: ``tests/harness/test_integrators.py``).
    ``B`` is formed as ``X^n + (X^n - X^{n-1}) / 3``, so that a fixed
    (Dirichlet) point, equal at both levels, keeps its coordinates exactly
    (``2 X^n - X^{n-1}`` does so anyway).

Both solve one linear system per step with the initial guess
``2 X^n - X^{n-1}`` (``X^0`` at the first step; ``warm_start="previous"``:
``X^n``), so a BDF2 step costs what an Euler step costs plus the scheme's
assembly at ``X*``, which is not the state it checks anyway.
"""

import time

import numpy as np

WARM_STARTS = ("extrapolate", "previous")


class Euler:
    """Semi-implicit Euler (2.1): ``X* = B = X^n``, ``dt = tau``.

    Parameters
    ----------
    warm_start : {"extrapolate", "previous"}
        Initial guess of the solver: ``2 X^n - X^{n-1}`` (``X^0`` at the
        first step), whose residual is O(tau^2) instead of the O(tau) of
        ``X^n``, or ``X^n``.

    Attributes
    ----------
    name, label : str
        Registry key and name in tables and legends.
    order : int
        The order in time.
    """

    name, label, order = "euler", "Euler", 1

    def __init__(self, warm_start="extrapolate"):
        if warm_start not in WARM_STARTS:
            raise ValueError(f"unknown warm_start {warm_start!r}; choose one of "
                             f"{', '.join(WARM_STARTS)}")
        self.warm_start = warm_start
        self._previous = None        # X^{n-1}, the flow's own numbering

    def evaluation(self, X, previous, tau):
        """``(X*, B, dt)`` of (I1) from ``X = X^n`` and ``previous = X^{n-1}``;
        ``None`` for the current state (:meth:`mcfbench.running.flow.Flow.system`)."""
        return None, None, tau

    def step(self, flow, solve):
        """Advance ``flow`` one time step.

        Parameters
        ----------
        flow : mcfbench.running.flow.Flow
        solve : callable
            ``solve(A, b, x0) -> (x, info)``; when it raises, the flow
            stays at ``n``.

        Returns
        -------
        info
            What ``solve`` returned.
        """
        X = flow.state
        previous = self._previous
        if previous is None:                       # the first step: Euler, X^{-1} = X^0
            at, base, dt = None, None, flow.tau
        else:
            at, base, dt = self.evaluation(X, previous, flow.tau)
        A, b = flow.system(at, base, dt)
        if previous is None or self.warm_start == "previous":
            x0 = X.copy()
        else:
            x0 = np.multiply(X, 2.0)               # 2 X^n - X^{n-1} in one new buffer
            x0 -= previous
        clock = time.perf_counter()
        if getattr(solve, "can_overwrite_x0", False):     # may iterate in x0, its own
            x, info = solve(A, b, x0, overwrite_x0=True)
        else:
            x, info = solve(A, b, x0)
        timings = getattr(flow, "timings", None)
        if timings is not None:
            timings["solve"] = timings.get("solve", 0.0) + time.perf_counter() - clock
        self._previous = X
        flow.advance(x)
        return info


class BDF2(Euler):
    """Linearly implicit BDF2 (I2), its first step by Euler (see the module docstring)."""

    name, label, order = "bdf2", "BDF2", 2

    def evaluation(self, X, previous, tau):
        return 2.0 * X - previous, X + (X - previous) / 3.0, 2.0 * tau / 3.0


INTEGRATORS = {cls.name: cls for cls in (Euler, BDF2)}
"""Name -> integrator class; ``integrator(warm_start=...)`` steps one flow."""


def get_integrator(name, **options):
    """A new integrator ``name`` (one per flow: it keeps ``X^{n-1}``).

    Raises
    ------
    ValueError
        Unknown name, listing the known ones.
    """
    if name not in INTEGRATORS:
        raise ValueError(f"unknown integrator {name!r}; choose one of "
                         f"{', '.join(INTEGRATORS)}")
    return INTEGRATORS[name](**options)
