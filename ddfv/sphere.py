"""The convergence experiment of Section 3.1: the shrinking unit sphere.

Level ``k`` is the icosphere refined ``k`` times with
``tau = 0.04 / 4**(k - 1)`` (``tau ~ h^2``) up to ``t_f = 0.08``.
"""

import time
from dataclasses import asdict, dataclass, field

import numpy as np

from .errors import SphereL2Error
from .stepping import simulate
from .surfaces import icosphere
from .variants import variant_options

T_FINAL = 0.08
TAU_LEVEL_1 = 0.04

# Table 3.1 as published: level -> (n_V, n_F, n_T, tau, N, L2 error, iter, EOC, CPU s)
PUBLISHED = {
    1: (122, 42, 80, 0.04, 2, 1.34e-02, 7, float("nan"), 0.02),
    2: (482, 162, 320, 0.01, 8, 3.26e-03, 34, 2.03, 0.13),
    3: (1922, 642, 1280, 0.0025, 32, 8.01e-04, 128, 2.03, 1.16),
    4: (7682, 2562, 5120, 0.000625, 128, 1.95e-04, 450, 2.04, 12.91),
    5: (30722, 10242, 20480, 0.00015625, 512, 4.66e-05, 1703, 2.07, 194.78),
}
PUBLISHED_COLUMNS = ("nV", "nF", "nT", "tau", "N", "l2_error", "iterations",
                     "eoc", "cpu_seconds")


def level_time_step(level, tau_level_1=TAU_LEVEL_1):
    """``tau = tau_1 / 4**(level - 1)``: the coupling ``tau ~ h^2`` of Table 3.1."""
    return tau_level_1 / 4.0 ** (level - 1)


def time_steps(t_final, tau):
    """Number of steps ``N = t_final / tau``; ``t_final`` must be a multiple of ``tau``."""
    steps = int(round(t_final / tau))
    if not np.isclose(steps * tau, t_final, rtol=1e-12, atol=0):
        raise ValueError(f"t_final = {t_final} is not a multiple of tau = {tau}")
    return steps


@dataclass
class SphereRun:
    """One row of Table 3.1.

    Attributes
    ----------
    level, nV, nF, nT, N : int
    variant : str
    tau : float
    l2_error : float
        (3.2); NaN when the run did not finish.
    iterations : int
        Total BiCGStab iterations (see :mod:`ddfv.solver`).
    cpu_seconds, wall_seconds : float
        Time of the flow (T initialisation, assembly, solves, error).
    status : str
        ``"ok"`` or the breakdown status of :class:`ddfv.Trajectory`.
    t_failed : float
        Time of the breakdown, NaN when ``status == "ok"``.
    t_min_barycentric : float
        The T monitor: smallest barycentric coordinate over all time levels.
    message : str
    t_monitor : list of float
        The T monitor at every time level reached (``n = 0, 1, ...``).
    """

    level: int
    variant: str
    nV: int
    nF: int
    nT: int
    tau: float
    N: int
    l2_error: float
    iterations: int
    cpu_seconds: float
    wall_seconds: float
    status: str
    t_failed: float
    t_min_barycentric: float
    message: str = ""
    t_monitor: list = field(default_factory=list, repr=False)

    def to_dict(self, series=True):
        """Fields as a dict; ``series=False`` leaves out ``t_monitor``."""
        row = asdict(self)
        if not series:
            del row["t_monitor"]
        return row


def sphere_run(level, *, tau=None, t_final=T_FINAL, radius=1.0, variant="paper",
               **flow_options):
    """Run the DDFV flow on the icosphere of ``level`` and measure (3.2).

    Parameters
    ----------
    level : int
        Refinement level (1 ... 5 in Table 3.1).
    tau : float, optional
        Time step; default :func:`level_time_step`.
    t_final : float
    radius : float
    variant : str
        A name of :data:`ddfv.variants.VARIANTS`.
    **flow_options
        Passed to :class:`ddfv.Flow` (``t_init``, ``rtol``, ``warm_start``,
        ``maxiter``).

    Returns
    -------
    SphereRun
    """
    tau = level_time_step(level) if tau is None else float(tau)
    steps = time_steps(t_final, tau)
    V, Fc = icosphere(level, radius)
    error = SphereL2Error(radius)
    cpu, wall = time.process_time(), time.perf_counter()
    options = {**variant_options(variant), **flow_options}
    traj = simulate(V, Fc, tau, steps, save_every=0, observer=error, **options)
    cpu, wall = time.process_time() - cpu, time.perf_counter() - wall
    ok = traj.status == "ok"
    return SphereRun(
        level=int(level), variant=variant, nV=len(V) + len(Fc), nF=len(V), nT=len(Fc),
        tau=tau, N=steps, l2_error=error.value if ok else float("nan"),
        iterations=int(traj.iterations.sum()), cpu_seconds=cpu,
        wall_seconds=wall, status=traj.status,
        t_failed=float("nan") if ok else traj.failed_step * tau,
        t_min_barycentric=float(traj.t_min_barycentric.min()),
        message=traj.message, t_monitor=traj.t_min_barycentric.tolist())


def sphere_table(levels, **options):
    """Table 3.1: :func:`sphere_run` for each level, EOC and published values.

    Parameters
    ----------
    levels : sequence of int
    **options
        Passed to :func:`sphere_run`.

    Returns
    -------
    pandas.DataFrame
        One row per level: the fields of :class:`SphereRun`, ``eoc`` (3.1)
        against the previous level when that is one coarser, and the
        published values as ``paper_*`` with ``l2_ratio = l2_error /
        paper_l2_error``.
    """
    import pandas as pd

    from .errors import eoc

    levels = [int(level) for level in levels]
    table = pd.DataFrame([sphere_run(level, **options).to_dict(series=False)
                          for level in levels])
    orders = eoc(table["l2_error"].to_numpy())
    consecutive = np.r_[False, np.diff(levels) == 1]
    table.insert(table.columns.get_loc("iterations") + 1, "eoc",
                 np.where(consecutive, orders, np.nan))
    published = pd.DataFrame.from_dict(PUBLISHED, orient="index",
                                       columns=PUBLISHED_COLUMNS)
    for column in ("l2_error", "iterations", "eoc", "cpu_seconds"):
        table[f"paper_{column}"] = table["level"].map(published[column])
    table["l2_ratio"] = table["l2_error"] / table["paper_l2_error"]
    return table
