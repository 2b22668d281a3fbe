"""The price of remeshing (#44 item 2): orders with and without, remesh calls, cost.

    python benchmarks/bench_remesh.py [SCHEME ...]     (default: cotan bgn ddfv-chord-bgn-carried)
    python benchmarks/bench_remesh.py --raw [SCHEME ...]   (default: mdr bgn ddfv-chord-bgn-carried)

For each scheme and problem with an exact answer where remeshing fires (the
anisotropic and the remeshed sphere, the catenoid), levels 1-3: the problem's error
and its order (EOC between levels) of ``NAME`` and ``NAME+remesh``, the remesh calls
(the rollbacks among them) and the vertices before -> after per level, and the wall
milliseconds of a remesh (the event's ``seconds``, its checks included) against the
run's per step, both measured in the same run.

With ``--raw``: ``NAME+remesh`` on every mesh of the raw corpus without thin features,
as the survival study runs it (40 steps of 0.1 h^2, its robust solver
``jacobi-direct``), each scheme warmed up first (its kernels compiled): the status,
the steps done, the remesh calls of the run (the rollbacks' included), the rollbacks
(a step that folded redone from the state before it remeshed:
``mcfbench.running.rollback``), the milliseconds a call and a step (the run's wall
time less its remeshes over its steps), and the remeshes' share of the run; a scheme
that cannot be built on a mesh (DDFV's redistribution on several components) is
reported ``refused`` with the reason.
"""

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from mcfbench.running.run import run  # noqa: E402

PROBLEMS = ("anisotropic_sphere", "remeshed_sphere", "catenoid")
LEVELS = (1, 2, 3)


def row(scheme, problem):
    errors, notes = [], []
    for level in LEVELS:
        result, traj = run(scheme, problem, level)
        metric = next(iter(result.metrics))
        errors.append(result.metrics[metric] if result.status == "ok" else np.nan)
        fired = [e for e in traj.events if e["event"] in ("remeshed", "rolled_back")]
        rollbacks = sum(e["event"] == "rolled_back" for e in fired)
        step = result.wall_seconds / max(1, result.steps_done)
        if fired:
            moved = "/".join(f"{e['vertices_before']}->{e['vertices_after']}" for e in fired[:2])
            call = np.mean([e["seconds"] for e in fired])
            notes.append(f"L{level}: {len(fired)} calls ({rollbacks} rollbacks; {moved}), "
                         f"max dist {max(e['distance'] for e in fired):.2g}, {call * 1e3:.2g} ms a "
                         f"call against {step * 1e3:.2g} ms a step")
        elif result.status != "ok":
            notes.append(f"L{level}: {result.status}")
    eoc = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    return errors, eoc, notes


def raw(schemes):
    from mcfbench.geometry import metrics
    from mcfbench.geometry.committed_meshes import RAW_DIR, raw_manifest
    from mcfbench.geometry.mesh_files import read_mesh
    from mcfbench.running.driver import simulate
    from mcfbench.running.remeshing import mesh_hook
    from mcfbench.running.schemes import get_scheme
    from mcfbench.running.solver import Solver

    meshes = [n for n, m in raw_manifest().items()
              if m["intake"] == "read" and not m["thin_features"]]
    print(f"{'scheme':32} {'mesh':26} {'status':10} {'steps':>5} {'calls':>5} "
          f"{'rollbacks':>9} {'ms/call':>8} {'ms/step':>8} {'remesh share':>12}")
    for base in schemes:
        scheme = get_scheme(f"{base}+remesh")
        for k, name in enumerate(meshes):
            V, F, _ = read_mesh(str(RAW_DIR / raw_manifest()[name]["file"]))
            tau = 0.1 * metrics.mean_edge_length(V, F) ** 2
            try:
                for warm_up in ((True, False) if k == 0 else (False,)):
                    traj = simulate(scheme.make(V, F, tau), 2 if warm_up else 40,
                                    solver=Solver(method="jacobi-direct"),
                                    remesh=mesh_hook(scheme, (V, F)))
            except ValueError as err:                 # the scheme cannot be built there
                print(f"{scheme.name:32} {name:26} refused: {err}", flush=True)
                continue
            calls = [e["seconds"] for e in traj.events
                     if e["event"] in ("remeshed", "rolled_back")]
            rollbacks = sum(e["event"] == "rolled_back" for e in traj.events)
            step = (traj.wall_seconds - sum(calls)) / max(1, traj.steps_done)
            call = np.mean(calls) if calls else np.nan
            print(f"{scheme.name:32} {name:26} {traj.status:10} {traj.steps_done:5d} "
                  f"{len(calls):5d} {rollbacks:9d} {call * 1e3:8.1f} {step * 1e3:8.1f} "
                  f"{sum(calls) / traj.wall_seconds:12.2f}", flush=True)


def main(schemes):
    print(f"{'scheme':34} {'problem':20} {'errors L1-L3':36} {'EOC':14} remeshing")
    for problem in PROBLEMS:
        for base in schemes:
            for scheme in (base, f"{base}+remesh"):
                errors, eoc, notes = row(scheme, problem)
                print(f"{scheme:34} {problem:20} "
                      f"{' '.join(f'{e:.3e}' for e in errors):36} "
                      f"{' '.join(f'{o:.2f}' for o in eoc):14} {'; '.join(notes)}", flush=True)


if __name__ == "__main__":
    if sys.argv[1:2] == ["--raw"]:
        raw(sys.argv[2:] or ["mdr", "bgn", "ddfv-chord-bgn-carried"])
    else:
        main(sys.argv[1:] or ["cotan", "bgn", "ddfv-chord-bgn-carried"])
