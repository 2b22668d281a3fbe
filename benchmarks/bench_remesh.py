"""The price of remeshing (#44 item 2): orders with and without, remesh calls, cost.

    python benchmarks/bench_remesh.py [SCHEME ...]     (default: cotan bgn ddfv-chord-bgn-carried)

For each scheme and problem with an exact answer where remeshing fires (the
anisotropic and the remeshed sphere, the catenoid), levels 1-3: the problem's error
and its order (EOC between levels) of ``NAME`` and ``NAME+remesh``, the remesh calls
and the vertices before -> after per level, and the wall milliseconds of a remesh
(the event's ``seconds``, its checks included) against the run's per step, both
measured in the same run.
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
        fired = [e for e in traj.events if e["event"] == "remeshed"]
        step = result.wall_seconds / max(1, result.steps_done)
        if fired:
            moved = "/".join(f"{e['vertices_before']}->{e['vertices_after']}" for e in fired[:2])
            call = np.mean([e["seconds"] for e in fired])
            notes.append(f"L{level}: {len(fired)} calls ({moved}), max dist "
                         f"{max(e['distance'] for e in fired):.2g}, {call * 1e3:.2g} ms a "
                         f"call against {step * 1e3:.2g} ms a step")
        elif result.status != "ok":
            notes.append(f"L{level}: {result.status}")
    eoc = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    return errors, eoc, notes


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
    main(sys.argv[1:] or ["cotan", "bgn", "ddfv-chord-bgn-carried"])
