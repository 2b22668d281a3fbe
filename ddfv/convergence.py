"""Convergence in time and in space separately (beyond Table 3.1).

Table 3.1 couples ``tau ~ h^2`` and sees order 2. Separately:

- in time, on a fixed mesh, halving ``tau`` should give order 1 (2.1):
  :func:`time_convergence` measures the distance of the final state to a
  reference computed with a much smaller ``tau`` on the same mesh, so the
  space error cancels;
- in space, with ``tau`` tiny and fixed, refining the mesh should give
  order 2: :func:`space_convergence` measures the error (3.2) against the
  exact sphere.
"""

import numpy as np
import pandas as pd

from .errors import SphereL2Error, eoc
from .geometry import covolume_areas, diamond_geometry
from .sphere import T_FINAL, sphere_run, time_steps
from .stepping import simulate
from .surfaces import icosphere
from .topology import diamond_mesh
from .variants import variant_options


def time_convergence(level, taus, *, reference_factor=8, t_final=T_FINAL,
                     variant="paper", **flow_options):
    """Error at ``t_final`` against a fine-``tau`` reference on one mesh.

    Parameters
    ----------
    level : int
        Icosphere level (fixed mesh).
    taus : sequence of float
        Time steps, each dividing ``t_final``; usually halved repeatedly.
    reference_factor : int
        The reference uses ``min(taus) / reference_factor``.
    t_final : float
    variant : str
    **flow_options
        Passed to :func:`ddfv.simulate`.

    Returns
    -------
    pandas.DataFrame
        Columns ``tau, N, error, eoc, l2_error, status``: ``error`` is
        ``sqrt(sum_i chi_i |X_i - X_i^ref|^2 / 2)`` at ``t_final`` (the
        covolume-weighted distance, both vertex families), ``eoc`` its order
        (3.1) between successive rows, ``l2_error`` the error (3.2) against
        the exact sphere.
    """
    V, F = icosphere(level)
    options = {**variant_options(variant), **flow_options}

    def final_state(tau):
        error = SphereL2Error()
        traj = simulate(V, F, tau, time_steps(t_final, tau), save_every=0, observer=error,
                        **options)
        l2 = error.value if traj.status == "ok" else np.nan
        return traj, np.concatenate([traj.F[-1], traj.T[-1]]), l2

    ref_traj, ref, _ = final_state(min(taus) / reference_factor)
    if ref_traj.status != "ok":
        raise RuntimeError(f"reference run failed: {ref_traj.message}")
    mesh = diamond_mesh(F, len(V))
    chi = np.concatenate(covolume_areas(
        mesh, diamond_geometry(mesh, ref[:len(V)], ref[len(V):])))
    rows = []
    for tau in taus:
        traj, X, l2 = final_state(tau)
        ok = traj.status == "ok"
        rows.append({
            "tau": tau, "N": time_steps(t_final, tau),
            "error": float(np.sqrt(0.5 * chi @ np.sum((X - ref) ** 2, axis=1))) if ok else np.nan,
            "l2_error": l2, "status": traj.status})
    table = pd.DataFrame(rows)
    table.insert(3, "eoc", eoc(table["error"].to_numpy()))
    return table


def space_convergence(levels, tau, *, t_final=T_FINAL, variant="paper", **flow_options):
    """Error (3.2) of the sphere on refined meshes with one small ``tau``.

    Returns
    -------
    pandas.DataFrame
        Columns ``level, nV, tau, N, l2_error, eoc, iterations, status``.
    """
    runs = [sphere_run(level, tau=tau, t_final=t_final, variant=variant, **flow_options)
            for level in levels]
    table = pd.DataFrame([{
        "level": r.level, "nV": r.nV, "tau": r.tau, "N": r.N,
        "l2_error": r.l2_error, "iterations": r.iterations, "status": r.status}
        for r in runs])
    table.insert(5, "eoc", eoc(table["l2_error"].to_numpy()))
    return table

