"""BGN with BDF-k in time on predictor surfaces (Jiang, Su and Zhang).

W. Jiang, C. Su, G. Zhang, "Stable BDF time discretization of BGN-based parametric
finite element methods for geometric flows", SIAM J. Sci. Comput. 46(5) (2024)
A2874-A2898, arXiv 2402.03641 ("BGN/BDFk"). BGN's equations (B1)-(B2) of
:mod:`baselines.bgn` with the difference quotient of (B1) replaced by the BDF-k
difference (Hairer, Norsett, Wanner, Solving ODEs I, Section III.1)::

    delta_k X^{m+1} = sum_{j=1}^k (1/j) nabla^j X^{m+1}
                    = alpha_0 (X^{m+1} - B_k),                                   (J1)
    k = 1: alpha_0 = 1,     B_1 = X^m
    k = 2: alpha_0 = 3/2,   B_2 = X^m + (X^m - X^{m-1}) / 3
    k = 3: alpha_0 = 11/6,  B_3 = X^m + (7 (X^m - X^{m-1}) - 2 (X^{m-1} - X^{m-2})) / 11

and the normals ``omega`` (B3), the lumped inner products and the stiffness all
taken on a predictor surface ``Gamma~^{m+1}`` (vertices ``X~^{m+1}``) instead of
``Gamma^m``::

    < delta_k X^{m+1} / tau, chi omega~ >_h~ - < kappa^{m+1}, chi >_h~ = 0       (J2)
    < kappa^{m+1} omega~, eta >_h~ + < grad_s X^{m+1}, grad_s eta >_~ = 0       (J3)

Eliminating ``kappa`` as in (B4) gives BGN's system at ``Gamma~^{m+1}`` with the
step ``dt = tau / alpha_0`` and the base ``B_k`` in place of ``tau`` and ``X^m``::

    (A~ + P~ / dt) X^{m+1} = P~ B_k / dt                                         (J4)

which is :meth:`baselines.bgn.BGNFlow.system` ``(at=X~^{m+1}, base=B_k, dt)``, the
same assembly (kernels, row scaling, Dirichlet rows).

The predictor (the authors build ``Gamma~^{m+1}`` "from lower-order BGN/BDF steps",
arXiv 2402.03641 v2, abstract and Section 2; read here as the recursion)::

    X~_1 = the BGN step (B4) from Gamma^m (operators on Gamma^m)
    X~_j = the solution of (J4) with k = j on the predictor X~_{j-1}, j = 2, ..., k-1
    X^{m+1} = the solution of (J4) with k on the predictor X~_{k-1}              (J5)

A BDF-(j-1) step from the exact history has local error O(tau^j) when its own
evaluation surface is O(tau^(j-1)) accurate, so ``X~_{k-1}`` is O(tau^k) close to
``X(t^{m+1})``: the operators' error in (J4) is then of the order of the scheme,
as with the extrapolation ``X* = sum_{j<k} nabla^j X^m`` of the harness's generic
BDF (``bgn@bdf2``, ``bgn@bdf3``; :mod:`mcfbench.running.integrators`, (I2)-(I3)),
which is (J4) with the extrapolated predictor, exactly. What differs is the
tangential position of the predictor's vertices: BGN's tangential motion is set anew
at every step by (B2) on the surface where the normals are taken; the extrapolation
amplifies a step-to-step alternation of it three- (k = 2) or sevenfold (k = 3),
whereas a BGN/BDF solve puts ``X~`` where BGN's own equidistribution puts it.
Cost: ``k`` linear systems per step (``k`` assemblies, ``k`` solves).

Start (an interpretation: not in what we could read of the paper). A stable k-step
method keeps order k when its starting values are O(tau^k) accurate (HNW I, Section
III.4). ``start="bgn"`` (BGN/BDF2's, the registry's): ``X^j``, ``j < k``, by the step
(J5) of order ``j``: ``X^1`` one BGN step, ``X^2`` (``k = 3``) one BGN/BDF2 step.
``X^1`` is O(tau^2) only, so BGN/BDF3's order with it is 2 in the limit (level-1
sphere to ``t = 0.04``: EOC 2.04, 2.00, 2.01 from tau 0.01). ``start="richardson"``:
``X^1 = 2 Z - W``, the Richardson extrapolation (HNW I, Section II.4) of one BGN step
``W`` and two half steps ``Z``, O(tau^3); then ``X^2`` by BGN/BDF2. It gives order 3
on the level-1 icosphere (EOC 3.06, 3.02, 3.01, 3.01), which BGN does not move
tangentially (symmetry), but where BGN does (level >= 2) an error that falls with
first order or not at all; so does a start from a fine run of the scheme itself
(level-2 sphere to ``t = 0.04``, ``X^1, X^2`` from 16 steps of ``tau / 16`` each:
volume errors 3.0e-5, 1.8e-5, 9.3e-6 from tau 0.005). The cause (derived in
:mod:`baselines.bgn_equilibrium`): BGN's tangential positions approach the
equilibrium (E2) one lagged iteration a step, by 1.6 % a step on the level-2 sphere,
so where a mesh is not at it they depend on the number of steps taken, not on the
time; any start but the run's own steps puts ``X^1`` elsewhere along the surface,
and the BDF base ``B_k`` takes that jump's normal part at the predictor's normals (a
curvature times its square), which does not vanish with tau. ``start="equilibrium"``
(BGN/BDF3's in the registry): ``X^0`` first moved along the surface to (E2)
(:func:`baselines.bgn_equilibrium.equilibrium`, to 1e-10 of the edge scale, at most
``EQUILIBRIUM_MAXIT`` iterations), then Richardson's ``X^1`` from there, ``X^2`` by
BGN/BDF2; the history is the relaxed ``X^0``. Order 3 where the steps' tangential
positions no longer depend on their number: level-2 sphere to ``t = 0.04``, volume
EOC 3.08, 3.32 (from ``X^0`` -0.85, 0.64, 1.01); the level-3 time study 3.04, 3.04,
3.09, 3.39. Where (E3) diverges (the real nut: BGN's tangential motion without the
normal motion that smooths the surface) the start is ``"bgn"``'s from ``X^0``
(``equilibrated`` False, order 2).

Energy: BGN's Euler step decreases the area (test (B1) with ``chi = kappa^{m+1}``,
(B2) with ``eta = X^{m+1} - X^m``: ``|Gamma^{m+1}| <= |Gamma^m|``, BGN 2008,
Theorem 2.3). (J2)-(J3) test to ``<grad X^{m+1}, grad delta_k X^{m+1}>_~ <= 0`` on
``Gamma~``, which bounds no area (BGN's bound needs the integral on ``Gamma^m`` and
the difference ``X^{m+1} - X^m``): no energy law for k >= 2, none claimed in the
abstract we could read; the area is checked at every step by the harness
(``area_grew``) and measured in ``baselines/README.md``.
"""

import numpy as np

from .bgn import BGNFlow
from .bgn_equilibrium import equilibrium, tangential_increment

ORDERS = (2, 3)
STARTS = ("bgn", "richardson", "equilibrium")

EQUILIBRIUM_TOL = 1e-10
"""``start="equilibrium"``: (E3) has converged when no vertex moves by more than this
fraction of the length ``sqrt(area / vertices)`` (:mod:`baselines.bgn_equilibrium`)."""

EQUILIBRIUM_MAXIT = 100
"""``start="equilibrium"``: the iterations of (E3) before the start falls back to
``"bgn"`` from ``X^0``, which it also does once a vertex has moved by the length
``sqrt(area / vertices)`` (measured: the level-2 and 3 icospheres converge in 9 and 38
iterations, moving vertices by 0.017 and 0.018, a tenth of that length and less; the
catenoid's meshes are at it; on the real nut (E3) diverges)."""

VANISHED = 1e-3
"""A predictor whose area is below this fraction of the current surface's ends the step
(:meth:`BGNBDFFlow.step`): the surface vanishes within it, and the next solve would be
taken on a surface of vanishing size (its matrix ill-conditioned, its rounding not
invariant under translation: measured, a 15-vertex sphere's last step solved at the
origin and failed one diameter away). That predictor is the new state, which the
harness's checks report as collapsed (its area tolerance is the same fraction of the
initial area)."""

BDF = {1: ((), 1, 1.0), 2: ((1,), 3, 2.0 / 3.0), 3: ((7, -2), 11, 6.0 / 11.0)}
"""``k -> (p, q, dt / tau)`` of (J1): ``B_k = X^m + sum_i p_i d_i / q``, ``d_i =
X^{m+1-i} - X^{m-i}``, ``dt / tau = 1 / alpha_0`` (BDF-k, HNW I, Section III.1)."""


def bdf_base(k, X, past, tau):
    """``(B_k, dt)`` of (J1) from ``X = X^m`` and ``past = (X^{m-1}, X^{m-2}, ...)``.

    Parameters
    ----------
    k : {1, 2, 3}
    X : (3, n) float array
    past : tuple of (3, n) float arrays
        At least ``k - 1`` of them, newest first.
    tau : float

    Returns
    -------
    base : (3, n) float array
        Equal to ``X`` exactly where every level is (fixed vertices).
    dt : float
    """
    p, q, share = BDF[k]
    shift = np.zeros_like(X)
    newer = X
    for p_i, older in zip(p, past):
        shift += p_i * (newer - older)
        newer = older
    return X + shift / q, share * tau


def surface_area(X, faces):
    """Area of the triangulated surface ``X`` (3, n), ``faces`` (m, 3)."""
    a, b, c = (X[:, faces[:, i]] for i in range(3))
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a, axis=0), axis=0).sum()


class BGNBDFFlow(BGNFlow):
    """BGN/BDF-``order`` (J1)-(J5): BGN's scheme stepped by BDF-k on predictor surfaces.

    It integrates in time itself (``integrates_itself``): the harness's Euler
    integrator hands its solver to :meth:`step` (``mcfbench.running.integrators``,
    ``Euler._own_step``), which solves ``order`` systems of BGN's form (J4) a step.

    Parameters
    ----------
    vertices : (n, 3) float array
    faces : (m, 3) int array
    tau : float
    order : {2, 3}
        ``k`` of BDF-k.
    start : {"bgn", "richardson", "equilibrium"}
        ``X^1`` of ``k = 3``: one BGN step, the Richardson extrapolation of BGN steps,
        or that from ``X^0`` relaxed to BGN's tangential equilibrium (module
        docstring, "Start"; ``k = 2``: BGN's step from the relaxed ``X^0``).
    scaling : {"mass", "none"}
        Row scaling of (J4), as :class:`baselines.bgn.BGNFlow`'s.
    """

    integrates_itself = True

    def __init__(self, vertices, faces, tau, *, order=2, start="bgn", scaling="mass"):
        if order not in ORDERS:
            raise ValueError(f"BGN/BDF-k is implemented for k in {ORDERS}, not {order!r}")
        if start not in STARTS:
            raise ValueError(f"unknown start {start!r}; choose one of {', '.join(STARTS)}")
        self.start = start
        super().__init__(vertices, faces, tau, scaling=scaling)
        self.order = int(order)
        self._past = ()              # X^{m-1}, X^{m-2}: newest first
        self.equilibrated = None
        """``start="equilibrium"``: whether (E3) converged at the first step (None
        before it); False: the run started as ``"bgn"`` from ``X^0``."""

    def step(self, solve_system):
        """Advance one time step (J5), the start-up steps included.

        Parameters
        ----------
        solve_system : callable
            ``solve_system((at, base, dt), x0) -> x`` (3, n): the solution of
            :meth:`system` ``(at, base, dt)`` from the initial guess ``x0``. When it
            raises, the flow stays at ``n``.
        """
        X, past, at = self.state, self._past, None
        extrapolated = self.start == "richardson"
        if self.start == "equilibrium" and not past:
            X = self._equilibrium(X)
            extrapolated = self.equilibrated
            at = X if self.equilibrated else None
        if extrapolated and self.order == 3 and not past:
            x = self._richardson_start(X, at, solve_system)
        else:
            x = self._predicted_step(X, at, min(len(past) + 1, self.order), solve_system)
        self._past = (X, *past)[:self.order - 1]
        self.advance(x)

    def _equilibrium(self, X):
        """``X^0`` moved tangentially to BGN's equilibrium (E2) (``start=
        "equilibrium"``); ``X`` itself when (E3) does not converge."""
        scale = np.sqrt(self.mass.sum() / X.shape[1])
        free = ~self.fixed

        def increment(at):
            g = self.geometry_at(at)
            return tangential_increment(self.assembler.laplacian(g.L_data),
                                        self._normals(g), at, free)

        relaxed, self.equilibrated, _ = equilibrium(
            increment, np.array(X), EQUILIBRIUM_TOL * scale, EQUILIBRIUM_MAXIT, scale)
        return relaxed if self.equilibrated else X

    def _predicted_step(self, X, at, k, solve_system):
        """``X^{m+1}`` of (J5) with ``k`` from ``X^m = X``: BGN/BDF-1, ..., BGN/BDF-k,
        each on the previous one's solution (the first on ``Gamma^m``: ``at``, None
        when ``X`` is the current state, whose operators are cached)."""
        past = self._past
        guess = 2.0 * X - past[0] if past else X.copy()
        for j in range(1, k + 1):
            base, dt = bdf_base(j, X, past, self.tau)
            guess = solve_system((at, base, dt), guess)
            if j < k and not surface_area(guess, self.faces) > VANISHED * self.mass.sum():
                return guess                       # the surface vanishes in this step
            at = guess
        return guess

    def _richardson_start(self, X, at, solve_system):
        """``X^1 = 2 Z - W`` from ``X^0 = X`` (``start="richardson"``, ``"equilibrium"``;
        ``at`` as in :meth:`_predicted_step`): ``W`` one BGN step, ``Z`` two half steps;
        fixed vertices keep ``X^0`` exactly."""
        tau = self.tau
        W = solve_system((at, X, tau), X.copy())
        Y = solve_system((at, X, tau / 2), X.copy())
        Z = solve_system((Y, Y, tau / 2), 2.0 * Y - X)
        x = np.multiply(Z, 2.0)
        x -= W
        return x
