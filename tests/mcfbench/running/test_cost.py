"""The cost of a run before it runs and the size guard (mcfbench/running/cost.py)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from mcfbench.cli import main
from mcfbench.running import cost
from mcfbench.running.problems import get_problem
from mcfbench.running.run import run
from mcfbench.running.schemes import get_scheme

SPHERE = get_problem("sphere")


@pytest.mark.parametrize("scheme, level, points, first", [
    ("cotan", 3, 642, 42), ("ddfv", 3, 642 + 1280, 42 + 80), ("bgn", 2, 162, 42)])
def test_size_of_a_level_without_building_its_mesh(scheme, level, points, first):
    unknowns, steps = cost.size(get_scheme(scheme), SPHERE, level)
    assert unknowns == pytest.approx(points, rel=0.05)          # 4^k from level 1
    assert steps == 2 * 4 ** (level - 1)                        # t_final / tau
    big, _ = cost.size(get_scheme(scheme), SPHERE, 12)          # no 168M-vertex mesh built
    assert big == first * 4 ** 11


@pytest.mark.parametrize("problem, level", [("real_nut", 0), ("real_bob", 1)])
def test_size_of_a_committed_mesh_from_its_manifest(problem, level):
    """The real meshes' counts come from the manifest, without reading the file: the
    same as the mesh's own."""
    problem = get_problem(problem)
    V, F = problem.mesh(level)
    assert cost.size(get_scheme("ddfv"), problem, level) == \
        cost.size(get_scheme("ddfv"), problem, level, mesh=(V, F))
    assert cost.size(get_scheme("cotan"), problem, level)[0] == len(V)


MEASURE = """
import json, sys
from pathlib import Path
from mcfbench.running.run import run

def status_mb(field):   # VmRSS: resident now; VmHWM: its peak since the last reset
    line = next(l for l in Path("/proc/self/status").read_text().splitlines()
                if l.startswith(field + ":"))
    return int(line.split()[1]) / 1024

start = status_mb("VmRSS")                        # after the imports
run(sys.argv[1], "sphere", 1)                     # the kernels loaded, first calls made
base = status_mb("VmRSS")
Path("/proc/self/clear_refs").write_text("5")     # VmHWM := VmRSS (the compilation's peak out)
result, _ = run(sys.argv[1], "sphere", int(sys.argv[2]))
peak = status_mb("VmHWM")
print(json.dumps([result.nV, result.N, peak - start, peak - base, result.cpu_seconds]))
"""

LARGEST = {"cotan": 5, "deturck": 5, "dual-mdr": 5, "bgn": 5, "kll": 5,
           "cotan-redistribute": 4, "ddfv-chord-carried": 4, "ddfv-chord-bgn-carried": 4,
           "ddfv-chord-redistribute-carried": 4}
"""Every kind of :data:`cost.COSTS` (cotan too, the vertex kind's lightest) by its largest
scheme (``benchmarks/bench_cost.py``) -> the level measured: 5 (2562 to 10 242
vertices), 4 for DDFV's kinds and the redistributing ones (7682 unknowns, 2562 vertices:
their level 5 takes 10-50 s here, too long for the quick tests; at level 5,
``ddfv-chord-bgn-carried`` peaked at 1.1 x the estimate of the kind it had before,
``ddfv``, and is at or below its kind's now, 2026-12-07)."""


def test_every_kind_is_in_the_measured_list():
    assert {cost.cost_class(scheme) for scheme in LARGEST} == set(cost.COSTS)


@pytest.mark.parametrize("scheme, level", LARGEST.items())
def test_the_estimate_is_at_or_above_the_measured_peak(scheme, level):
    """The sphere in a fresh process, after a level-1 run (its kernels loaded): the
    peak resident memory above the process's after the imports is at or below the
    guard's estimate (the fixed part and the fit); the part that grows with the mesh
    (the peak above the warmed-up process) and, at level 5, the CPU time have the
    order of magnitude of the fits. (At level 5, ``dual-mdr`` peaked at 1.1 x the
    estimate of the kind it had before, ``vertex``: 166 MB against 149 MB.)"""
    root = Path(__file__).resolve().parents[3]
    out = subprocess.run([sys.executable, "-c", MEASURE, scheme, str(level)], cwd=root,
                         check=True, text=True, capture_output=True,
                         env={**os.environ, "PYTHONPATH": str(root)})
    n, steps, peak, growth, seconds = json.loads(out.stdout)
    estimate = cost.estimate(get_scheme(scheme), n, steps)
    assert estimate.memory_mb >= peak, (estimate, peak)
    assert 1 / 3 < (estimate.memory_mb - cost.FIXED_MB) / growth < 3, (estimate, growth)
    if level == 5:      # the fits' levels (below, fixed costs dominate the steps)
        assert 1 / 10 < estimate.seconds / seconds < 10, (estimate, seconds)


def test_a_run_above_the_available_memory_is_refused_naming_both(monkeypatch):
    monkeypatch.setattr(cost, "available_mb", lambda: 100.0)
    with pytest.raises(cost.RunTooLarge) as err:
        run("ddfv", "sphere", 8)
    estimate = cost.estimate(get_scheme("ddfv"), *cost.size(get_scheme("ddfv"), SPHERE, 8))
    message = str(err.value)
    assert f"about {estimate.unknowns:,} unknowns" in message
    assert f"estimated to need {estimate.memory_mb / 1024:.3g} GB of memory" in message
    assert "but 100 MB is available" in message and "--force" in message
    assert isinstance(err.value, ValueError)


def test_force_runs_it_anyway(monkeypatch):
    monkeypatch.setattr(cost, "available_mb", lambda: 1.0)
    with pytest.raises(cost.RunTooLarge, match="1 MB is available"):
        run("cotan", "sphere", 1)
    result, _ = run("cotan", "sphere", 1, force=True)
    assert result.status == "ok"


def test_the_command_line_refuses_level_12_in_one_line(monkeypatch, capsys):
    monkeypatch.setattr(cost, "available_mb", lambda: 16 * 1024.0)
    assert main(["study", "sphere", "--levels", "12", "--scheme", "cotan"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: cotan on the sphere at level 12: about 176,160,768 "
                          "unknowns") and "16 GB is available" in err
    assert "Traceback" not in err and len(err.splitlines()) == 1


@pytest.mark.parametrize("scheme, kind", [
    ("cotan", "vertex"), ("cmcf", "vertex"), ("cotan-redistribute", "vertex, redistributing"),
    ("ddfv-chord-carried@bdf2", "ddfv"), ("ddfv-redistribute", "ddfv, redistributing"),
    ("bgn@bdf2", "bgn"), ("kll@bdf3", "kll"), ("dual-mdr", "dual-mdr"),
    ("deturck", "vertex"), ("ddfv-chord-bgn-carried", "ddfv, tangential"),
    ("ddfv-chord-mdr-carried@bdf2", "ddfv, tangential")])
def test_cost_class(scheme, kind):
    assert cost.cost_class(scheme) == kind
