"""The time integrators, one for every scheme: semi-implicit Euler and linearly implicit BDF2, BDF3.

A scheme provides its spatial operators at a state (:meth:`SchemeFlow.system
<mcfbench.running.flow.SchemeFlow.system>`): the linear system of

    M(X*) (X^{n+1} - B) / dt + L(X*) X^{n+1} = g(X*)                        (I1)

for an evaluation state ``X*``, a base state ``B`` and a step ``dt`` (``M``
its mass-like operator, ``L`` its stiffness, ``g`` what it adds
explicitly, e.g. the elimination (3.6) or a tangential velocity, each
assembled at ``X*``). An integrator chooses the three:

``euler`` (:class:`Euler`, the paper's semi-implicit step (2.1), the default)
    ``X* = B = X^n``, ``dt = tau``: first order.
``bdf2``, ``bdf3`` (:class:`BDF2`, :class:`BDF3`: linearly implicit BDF-k with the
operators at the extrapolated state, Kovacs, Li, Lubich, Numer. Math. 143 (2019),
(4.2); Akrivis, Lubich, Numer. Math. 131 (2015) 713-735)
    BDF-k (Hairer, Norsett, Wanner, Solving ODEs I, Section III.1) replaces the time
    derivative at ``t^{n+1}`` by ``sum_{j=1}^k (1/j) nabla^j X^{n+1} / tau =
    sum_{i=0}^k alpha_i X^{n+1-i} / tau`` and takes the operators at the extrapolation
    ``X* = sum_{j=0}^{k-1} nabla^j X^n`` (exact for polynomials of degree ``k - 1``,
    so ``X* - X(t^{n+1}) = O(tau^k)``). Dividing by ``alpha_0 / tau`` gives (I1)
    with ``dt = tau / alpha_0`` and ``B = -sum_{i>=1} alpha_i X^{n+1-i} / alpha_0``
    (weights summing to 1)::

        k = 2:  (3 X^{n+1} - 4 X^n + X^{n-1}) / (2 tau)                      (I2)
                X* = 2 X^n - X^{n-1},  B = (4 X^n - X^{n-1}) / 3,  dt = 2 tau / 3
        k = 3:  (11/6 X^{n+1} - 3 X^n + 3/2 X^{n-1} - 1/3 X^{n-2}) / tau    (I3)
                X* = 3 X^n - 3 X^{n-1} + X^{n-2},
                B = (18 X^n - 9 X^{n-1} + 2 X^{n-2}) / 11,  dt = 6 tau / 11

    (:func:`bdf_formula` computes them in exact fractions.) ``B`` is formed from the
    differences ``d_i = X^{n+1-i} - X^{n-i}``, ``B = X^n + d_1 / 3`` (k = 2),
    ``B = X^n + (7 d_1 - 2 d_2) / 11`` (k = 3), and ``X*`` as the integer
    combination above, so that a fixed (Dirichlet) point, equal at every level,
    keeps its coordinates exactly.

    Start-up (Hairer, Norsett, Wanner, Solving ODEs I, Section III.4: a stable
    k-step method of order p converges with order p when its starting values are
    ``O(tau^p)`` accurate): BDF2's ``X^1`` is an Euler step (local error
    ``O(tau^2)``). BDF3 needs ``X^1`` and ``X^2`` to ``O(tau^3)``, which an Euler
    step would spoil (measured: EOC 2.0 on the toy scheme of
    ``tests/mcfbench/running/test_integrators.py``): ``X^1 = 2 Z - W`` is the Richardson
    extrapolation of the Euler step ``W`` (step ``tau``) and two Euler half steps
    ``Z`` (local errors ``C tau^2 + O(tau^3)`` and ``C tau^2 / 2 + O(tau^3)``;
    Hairer, Norsett, Wanner I, Section II.4), three solves; ``X^2`` is a BDF2 step
    (I2) (local error ``O(tau^3)``). BDF4-5 (Kovacs, Li and Lubich use k <= 5)
    would need starting values to ``O(tau^4)``, ``O(tau^5)``, which one Richardson
    step of Euler does not give: not implemented (:func:`bdf_formula` stops at
    k = 3). BDF2 keeps its Euler start (its results
    unchanged, bitwise), although that start dominates its error: with the
    extrapolated-Euler start instead, ``ddfv-chord`` on the level-1 sphere (the
    study below) has 2.9e-5 instead of 7.9e-4 at tau = 0.005, but EOC 1.5 and
    1.8 over the next two halvings. The half step's state is a solution of the
    scheme's system that is not handed to :meth:`SchemeFlow.advance`, so a scheme's
    post-processing there (DDFV's carried T-vertices) does not apply to it.

    Measured (shrinking sphere, level-1 icosphere, ``t = 0.02``, taus 0.005 /
    0.0025 / 0.00125 against tau / 8, sparse LU; ``tests/mcfbench/running/test_integrators.py``):
    pointwise EOC 2.97-3.18 for every scheme but the DDFV variants with carried
    T-vertices, which fall to 1.1-1.4 at errors of 3e-6 (their volume EOC
    2.9-3.1; with an Euler first step they keep order 2, and carrying the half
    step's T-vertices too does not restore order 3: cause not found). ``cotan``
    to ``t = 0.04``, taus 0.01 ... 0.000625 (0.0003125): level 1 3.03, 2.99, 3.00,
    3.00; level 2 3.05, 2.88, 2.94, 2.97; level 3 2.86, 2.30, 2.60, 2.77, 2.88
    (volume 2.98-3.03 throughout): the order is reached once ``tau`` is small
    against the mesh's stiffest mode (``h^2``), from 0.00125 on level 3. The
    beyond study's time study (level 3, ``t = 0.08``, taus 0.01 ... 0.000625,
    reference tau / 8, BiCGStab rtol 1e-12: ``beyond.time_study.rtol``; at the
    top-level 1e-9 the accepted residuals of its steps were the floor of the
    smallest errors, ``cotan`` 2.31, 2.43, 2.66, 2.24, volume EOC -2.35 at the
    end; 2026-11-26): ``cotan`` (and ``cotan-intrinsic``, the sphere's mesh is
    Delaunay) 2.30, 2.42, 2.61, 2.77 (volume 2.97-3.00), ``deturck`` 2.98,
    3.00, 3.01, 3.02, ``kll`` 2.79, 3.90, 3.77, 1.36 (volume alike; two more
    halvings: 2.47, 2.77), ``mdr`` 2.98, 2.95, 2.01, 0.26 (volume 2.98-3.01: its
    tangential motion, set anew at every step, floors the pointwise error at
    4e-7), ``ddfv`` 2.79, 1.80, 2.08, 2.33 (volume 2.94-2.82), ``ddfv-chord``
    2.95, 1.54, 2.01, 2.29 (volume 2.98-2.93); ``bgn``'s reference run (tau
    7.8e-5) grows the area at step 38. Neither the reference (tau / 32 or the
    sparse LU at rtol 1e-13: the same EOCs to the digits shown) nor the solver
    limits these orders. The start-up does not limit them either, but it is a
    large part of the error: started from the reference's ``X^1``, ``X^2``
    (tau / 8 steps) instead of (extrapolated Euler, BDF2), ``cotan``'s errors are
    3 x smaller at the same EOCs (2.37, 2.33, 2.61, 2.79; the start-up's
    ``X^1`` error falls by 3.9, 3.9, 4.6, 5.6 per halving, not yet 8: stiff
    modes, ``tau`` not small against ``h^2``), and ``kll``'s EOCs become
    2.67, 2.72, 2.69, 2.81: its non-monotone EOCs are the start-up error
    cancelling the bulk error near tau 0.00125, not a lower order. That start-up
    error is large because ``kll``'s ``nu^0``, ``H^0`` from the mesh are rough (stiff
    modes, where the extrapolated Euler step is not yet asymptotic) and its ``X``
    keeps what they leave; from smooth ``nu^0``, ``H^0`` the start-up is O(tau^3)
    (errors / 7-8 per halving) and the EOCs are 2.91, 2.95, 2.98, 2.99
    (``baselines/README.md``, kll, "Order in time").
    **BGN with BDF3 inverts** once tau is small: level-3 sphere to ``t = 0.08``
    ok at tau 0.01 and 0.0025 (smallest angle 54 -> 6.3 degrees), inverted at
    step 46 with tau 0.000625; Table 3.1's level 4 inverted at step 39 of 128
    (sparse LU). Its tangential motion, set anew at every step, is extrapolated
    sevenfold (below).

    Stability: BDF1-2 are A-stable, BDF3-6 only A(alpha)-stable (alpha = 86.03,
    73.35, 51.84, 17.84 degrees for k = 3-6, Hairer, Wanner, Solving ODEs II,
    Section V.2; no A-stable linear multistep method has order > 2, Dahlquist). For MCF the
    stiffness is symmetric positive semi-definite against the lumped mass, so the
    spectrum of the frozen linear part lies on the negative real axis, inside
    every such sector; Akrivis and Lubich prove stability of linearly implicit
    BDF1-5 for quasi-linear parabolic problems by the multipliers of Nevanlinna and
    Odeh (BDF6 needs others: Akrivis, Chen, Yu, Zhou, SIAM J. Numer. Anal. 59
    (2021)), the setting of Kovacs, Li, Lubich (k <= 5). The
    operators at ``X*`` are not frozen, and BDF3's extrapolation amplifies a
    step-to-step oscillation sevenfold (``|3| + |-3| + |1|``) against BDF2's
    threefold, which matters for schemes whose tangential motion is not smooth
    in time (BGN, ``baselines/README.md``).

A flow that integrates in time itself (``integrates_itself``: BGN/BDF-k on predictor
surfaces, :mod:`baselines.bgn_bdf`) is stepped by the Euler integrator's
:meth:`Euler._own_step` alone: it solves its own systems with the run's solver.

Every integrator solves one linear system per step (the BDF3 start-up: three
at the first step) with the initial guess ``2 X^n - X^{n-1}`` (``X^0`` at the
first step; BDF3, from the third step: its ``X*``; ``warm_start="previous"``:
``X^n``), so a BDF step costs what an Euler step costs plus the scheme's
assembly at ``X*``, which is not the state it checks anyway.
"""

import time
from dataclasses import replace
from fractions import Fraction
from math import comb

import numpy as np

WARM_STARTS = ("extrapolate", "previous")


def bdf_formula(k):
    """The coefficients of (I1) for BDF-``k``, exact.

    Parameters
    ----------
    k : int
        1, 2 or 3.

    Returns
    -------
    extrapolation : tuple of int
        ``e_i`` of ``X* = sum_{i=0}^{k-1} e_i X^{n-i}``, ``e_i = (-1)^i C(k, i+1)``.
    differences : tuple of int
        ``p_i`` of ``B = X^n + sum_{i=1}^{k-1} p_i d_i / q``,
        ``d_i = X^{n+1-i} - X^{n-i}``.
    denominator : int
        ``q``.
    step : fractions.Fraction
        ``dt / tau = 1 / alpha_0``, ``alpha_0 = sum_{j=1}^k 1/j``.

    Examples
    --------
    >>> bdf_formula(3)
    ((3, -3, 1), (7, -2), 11, Fraction(6, 11))
    """
    if k not in (1, 2, 3):
        raise ValueError(f"BDF-k is implemented for k = 1, 2, 3, not {k!r}")
    alpha = [sum(Fraction((-1) ** i * comb(j, i), j) for j in range(max(i, 1), k + 1))
             for i in range(k + 1)]                          # alpha_i of X^{n+1-i}
    weights = [-a / alpha[0] for a in alpha[1:]]             # of X^n, ..., X^{n+1-k}
    shares = [-sum(weights[i:]) for i in range(1, k)]        # of d_1, ..., d_{k-1}
    q = max([1, *(c.denominator for c in shares)])
    return (tuple((-1) ** i * comb(k, i + 1) for i in range(k)),
            tuple(int(c * q) for c in shares), q, 1 / alpha[0])


class Euler:
    """Semi-implicit Euler (2.1): ``X* = B = X^n``, ``dt = tau``.

    Parameters
    ----------
    warm_start : {"extrapolate", "previous"}
        Initial guess of the solver: the extrapolation ``2 X^n - X^{n-1}``
        (``X^0`` at the first step; BDF3: its ``X*``), whose residual is
        O(tau^2) instead of the O(tau) of ``X^n``, or ``X^n``. When the flow
        moved the last solution ``x^n`` before accepting it as ``X^n`` (DDFV's
        carried T-vertices, a tangential motion of the F-vertices), the
        extrapolation is that of the solve's own increment, ``X^n + (x^n -
        X^{n-1})``, i.e. ``2 X^n - X^{n-1}`` plus ``x^n - X^n``: the solve moves the
        carried T-vertices back along the surface by about the same amount every
        step, which ``2 X^n - X^{n-1}`` of the carried states leaves out (catenoid
        level 2, ``ddfv-chord-carried``: 1.62 BiCGStab iterations a step against
        5.13). A flow that accepts the solution as it is (its state shares the
        solution's memory) gets ``2 X^n - X^{n-1}`` itself, bit for bit.

    Attributes
    ----------
    name, label : str
        Registry key and name in tables and legends.
    order : int
        The order in time, ``k`` of BDF-k: the formula uses ``X^n, ..., X^{n+1-k}``.
    """

    name, label, order = "euler", "Euler", 1

    def __init__(self, warm_start="extrapolate"):
        if warm_start not in WARM_STARTS:
            raise ValueError(f"unknown warm_start {warm_start!r}; choose one of "
                             f"{', '.join(WARM_STARTS)}")
        self.warm_start = warm_start
        self._past = ()      # X^{n-1}, X^{n-2}, ... (newest first), the flow's own numbering
        self._moved = None   # the last solution less the state the flow made of it, or None

    def evaluation(self, X, past, tau):
        """``(X*, B, dt)`` of (I1) from ``X = X^n`` and ``past = (X^{n-1}, ...)``;
        ``None`` for the current state (:meth:`mcfbench.running.flow.SchemeFlow.system`)."""
        return None, None, tau

    def initial_guess(self, X, past, at):
        """The solver's initial guess from ``X^n``, ``past`` and the step's ``X*`` (``at``)."""
        if not past or self.warm_start == "previous":
            return X.copy()
        x0 = np.multiply(X, 2.0)               # 2 X^n - X^{n-1} in one new buffer
        x0 -= past[0]
        return x0

    def step(self, flow, solve):
        """Advance ``flow`` one time step.

        Parameters
        ----------
        flow : mcfbench.running.flow.SchemeFlow
        solve : callable
            ``solve(A, b, x0) -> (x, info)``; when it raises, the flow
            stays at ``n``.

        Returns
        -------
        info
            What ``solve`` returned (the BDF3 start-up: the last solve's, its
            ``iterations`` those of its three solves).
        """
        if getattr(flow, "integrates_itself", False):
            return self._own_step(flow, solve)
        X, past = flow.state, self._past
        if not past and self.order > 2:
            x, info = self._extrapolated_euler(flow, solve)
        else:
            at, base, dt = self.evaluation(X, past, flow.tau)
            x0 = self.initial_guess(X, past, at)
            if self._moved is not None and past and self.warm_start == "extrapolate":
                x0 += self._moved
            x, info = self._solve(flow, solve, (at, base, dt), x0)
        self._past = (X, *past)[:max(self.order - 1, 1)]
        flow.advance(x)
        state = flow.state
        self._moved = None if np.may_share_memory(state, x) else x - state
        return info

    def _own_step(self, flow, solve):
        """The step of a flow that integrates in time itself (``integrates_itself``: its
        step needs solves at states only it knows, e.g. the predictor surfaces of
        :mod:`baselines.bgn_bdf`): ``flow.step(solve_system)`` calls
        ``solve_system((at, base, dt), x0) -> x`` for each of its systems
        (:meth:`SchemeFlow.system`), timed and solved as every other step's, and
        advances itself. Only the Euler integrator steps such a flow (no generic BDF
        on top of its own).

        Returns
        -------
        info
            Its last solve's, ``iterations`` those of all its solves.
        """
        if self.name != "euler":
            raise ValueError(f"the flow {type(flow).__name__} integrates in time itself; "
                             f"it cannot be stepped by the integrator {self.name!r}")
        infos = []

        def solve_system(system, x0):
            x, info = self._solve(flow, solve, system, x0)
            infos.append(info)
            return x

        flow.step(solve_system)
        return replace(infos[-1], iterations=sum(info.iterations for info in infos))

    def _solve(self, flow, solve, system, x0):
        """Solve ``flow.system(*system)`` from ``x0``; the seconds go to the flow's
        ``timings["solve"]``."""
        A, b = flow.system(*system)
        clock = time.perf_counter()
        if getattr(solve, "can_overwrite_x0", False):     # may iterate in x0, its own
            x, info = solve(A, b, x0, overwrite_x0=True)
        else:
            x, info = solve(A, b, x0)
        timings = getattr(flow, "timings", None)
        if timings is not None:
            timings["solve"] = timings.get("solve", 0.0) + time.perf_counter() - clock
        return x, info

    def _extrapolated_euler(self, flow, solve):
        """``X^1 = 2 Z - W`` (the BDF3 start-up, module docstring): ``W`` one Euler
        step, ``Z`` two Euler half steps, local error O(tau^3); fixed points keep
        ``X^0`` exactly (``2 x - x = x``)."""
        X, tau = flow.state, flow.tau
        W, first = self._solve(flow, solve, (None, None, tau), X.copy())
        Y, second = self._solve(flow, solve, (None, None, tau / 2), X.copy())
        Z, info = self._solve(flow, solve, (Y, Y, tau / 2),
                              self.initial_guess(Y, (X,), None))
        x = np.multiply(Z, 2.0)
        x -= W
        iterations = first.iterations + second.iterations + info.iterations
        return x, replace(info, iterations=iterations)


class BDF(Euler):
    """Linearly implicit BDF-``order`` ((I2), (I3)), its start-up steps in the module
    docstring."""

    def evaluation(self, X, past, tau):
        if not past:                                  # the first step (BDF2): Euler
            return super().evaluation(X, past, tau)
        e, p, q, step = bdf_formula(min(len(past) + 1, self.order))   # start-up: lower k
        at = np.multiply(X, float(e[0]))
        d = X - past[0]
        shift = np.multiply(d, float(p[0]))
        for i, (X_i, e_i) in enumerate(zip(past, e[1:]), start=1):
            at += e_i * X_i
            if i < len(p):
                d = X_i - past[i]
                shift += p[i] * d
        return at, X + shift / q, step.numerator * tau / step.denominator

    def initial_guess(self, X, past, at):
        if self.order > 2 and len(past) > 1 and self.warm_start == "extrapolate":
            return at.copy()
        return super().initial_guess(X, past, at)


class BDF2(BDF):
    """Linearly implicit BDF2 (I2), its first step by Euler (module docstring)."""

    name, label, order = "bdf2", "BDF2", 2


class BDF3(BDF):
    """Linearly implicit BDF3 (I3), its first step by extrapolated Euler and its second
    by BDF2 (module docstring)."""

    name, label, order = "bdf3", "BDF3", 3


INTEGRATORS = {cls.name: cls for cls in (Euler, BDF2, BDF3)}
"""Name -> integrator class; ``integrator(warm_start=...)`` steps one flow."""


def get_integrator(name, **options):
    """A new integrator ``name`` (one per flow: it keeps ``X^{n-1}, ...``).

    Raises
    ------
    ValueError
        Unknown name, listing the known ones.
    """
    if name not in INTEGRATORS:
        raise ValueError(f"unknown integrator {name!r}; choose one of "
                         f"{', '.join(INTEGRATORS)}")
    return INTEGRATORS[name](**options)
