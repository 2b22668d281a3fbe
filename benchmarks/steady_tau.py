"""Does a steady-state problem need ``tau ~ h^2``? Its final errors with the problem's
time rule against a step that does not shrink with the level (issue 32: the catenoid's
level 3 is 6 000 steps).

    nice python benchmarks/steady_tau.py --problem catenoid --levels 1 2 3
    nice python benchmarks/steady_tau.py --levels 2 --schemes cotan kll --t-final 4 \\
        --rows out.jsonl                       # more runs later: rows appended

The idea examined: a step ``(X - B) / dt + L(X*) X = g(X*)`` (every integrator of
``mcfbench.running.integrators``: ``X* = B = X`` at a fixed point) has the fixed points
``L(X) X = g(X)`` whatever ``dt``, so a metric of the steady state should not depend on
``tau``. The measurement says when it does anyway: the fixed point also depends on
``tau`` when a step ends with a projection that ``tau`` does not scale (DDFV's carried
T-vertices, its BGN/MDR tangential move), the fixed points form a continuum when a
scheme sets only the normal velocity (the elimination (3.6), MDR, KLL: where the flow
stops along it depends on the path, so on ``tau``), and a run may not reach its fixed
point by ``t_final`` (the slow tangential drift of the cotangent schemes).

Each run is :func:`mcfbench.running.run.run` (BiCGStab, rtol 1e-9, the problem's
steady-state stop) with ``tau`` of the rule: ``level`` the problem's own, ``fixed``
``tau_1`` at every level, ``h`` ``tau_1 / 2^(k-1)``; ``--t-final`` another final time
for every rule. Per scheme and level the table gives every metric under each rule with
its relative difference from the problem's rule, the steps, the CPU seconds, whether the
run reached the steady state and its largest vertex speed at the end; then the EOC of
every metric under each rule. One JSON row per run goes to ``--rows`` (appended; the
table is made from every row there).
"""

import argparse
import json
import math
import os
from pathlib import Path

from _harness import THREAD_VARIABLES, machine_line, one_core  # noqa: E402

for _name in THREAD_VARIABLES:
    os.environ.setdefault(_name, "1")

from mcfbench.geometry.exact import eoc  # noqa: E402
from mcfbench.geometry.metrics import max_speed  # noqa: E402
from mcfbench.running.problems import get_problem  # noqa: E402
from mcfbench.running.run import run  # noqa: E402
from mcfbench.running.schemes import SCHEMES  # noqa: E402
from mcfbench.storage.memory import tune_malloc  # noqa: E402

RULES = {"level": None, "fixed": lambda tau_1, k: tau_1,
         "h": lambda tau_1, k: tau_1 / 2.0 ** (k - 1)}
"""Rule -> ``tau(tau_1, level)`` (``None``: the problem's own)."""


class _LastSpeed:
    """Observer: the largest vertex speed between the last two time levels."""

    def __init__(self):
        self.previous, self.speed = None, math.nan

    def __call__(self, flow):
        V = flow.vertices.copy()
        if self.previous is not None:
            self.speed = max_speed(self.previous, V, flow.tau)
        self.previous = V


def measure(name, problem, level, rule, t_final=None):
    """One run's row: rule, tau, status, steps, CPU seconds, steady, final speed, metrics
    (``name`` a scheme, ``NAME@INTEGRATOR`` included)."""
    scheme, _, integrator = name.partition("@")
    tau = problem.tau(level) if RULES[rule] is None else RULES[rule](problem.tau_1, level)
    speed = _LastSpeed()
    result, _ = run(scheme, problem, level, tau=tau, t_final=t_final,
                    integrator=integrator or None, observers=[speed])
    return {"problem": problem.name, "scheme": name, "level": level, "rule": rule,
            "t_final": t_final, "tau": tau, "status": result.status,
            "steps": result.steps_done, "cpu": result.cpu_seconds,
            "steady": result.steady, "speed": speed.speed,
            "metrics": {k: v for k, v in result.metrics.items() if v is not None}}


def table(rows):
    """The lines of the comparison: per scheme and level, then the EOC per rule."""
    runs = {(r["scheme"], r["level"], r["rule"]): r for r in rows}
    schemes = list(dict.fromkeys(r["scheme"] for r in rows))
    rules = list(dict.fromkeys(r["rule"] for r in rows))
    levels = sorted({r["level"] for r in rows})
    base = "level" if "level" in rules else rules[0]
    lines = [f"rules: {', '.join(rules)} (relative difference against {base}); per rule: "
             f"status, steps, CPU s, steady, final speed, metrics"]
    for scheme in schemes:
        for level in levels:
            ref = runs.get((scheme, level, base))
            for rule in rules:
                r = runs.get((scheme, level, rule))
                if r is None:
                    continue
                values = []
                for k, v in r["metrics"].items():
                    w = ref["metrics"].get(k) if ref else None
                    diff = abs(v - w) / abs(w) if w and math.isfinite(v) and rule != base \
                        else None
                    values.append(f"{k} {v:.5e}" + (f" ({diff:.1e})" if diff is not None else ""))
                lines.append(f"{scheme:32s} L{level} {rule:5s} tau {r['tau']:.3g} "
                             f"{r['status']:9s} {r['steps']:6d} {r['cpu']:7.2f} s "
                             f"{'steady' if r['steady'] else '      '} {r['speed']:.1e}  "
                             + ", ".join(values))
    if len(levels) < 2:
        return lines
    lines.append("EOC per rule (levels " + "-".join(map(str, levels)) + ")")
    for scheme in schemes:
        for rule in rules:
            series = [runs.get((scheme, level, rule)) for level in levels]
            if any(r is None for r in series):
                continue
            names = [k for k in series[0]["metrics"] if "error" in k]
            orders = {k: eoc([r["metrics"].get(k, math.nan) for r in series], levels,
                             [r["status"] == "ok" for r in series])[1:] for k in names}
            lines.append(f"{scheme:32s} {rule:5s} " + "; ".join(
                f"{k} " + " ".join(f"{o:.2f}" for o in v) for k, v in orders.items()))
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--problem", default="catenoid")
    parser.add_argument("--schemes", nargs="+", default=[
        *SCHEMES, "cotan@bdf2", "cotan@bdf3", "ddfv-chord-carried@bdf2"])
    parser.add_argument("--levels", nargs="+", type=int, default=[1, 2, 3])
    parser.add_argument("--rules", nargs="+", choices=RULES, default=["level", "fixed"])
    parser.add_argument("--t-final", type=float, default=None,
                        help="another final time for every rule (default the problem's)")
    parser.add_argument("--rows", type=Path, default=Path("steady_tau.jsonl"))
    args = parser.parse_args()
    tune_malloc()
    one_core()
    print(machine_line())
    problem = get_problem(args.problem)
    for rule in args.rules:
        for level in args.levels:
            for scheme in args.schemes:
                row = measure(scheme, problem, level, rule, args.t_final)
                with args.rows.open("a") as out:
                    out.write(json.dumps(row) + "\n")
                print(f"{scheme} level {level} {rule}: {row['status']}, {row['steps']} steps, "
                      f"{row['cpu']:.3g} s CPU", flush=True)
    rows = [json.loads(line) for line in args.rows.read_text().splitlines()]
    print("\n".join(table([r for r in rows if r["problem"] == problem.name
                           and r["t_final"] == args.t_final])))


if __name__ == "__main__":
    main()
