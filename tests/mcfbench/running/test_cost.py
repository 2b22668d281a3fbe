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
import json
from pathlib import Path
from mcfbench.running.run import run

def anonymous_mb():   # not file-backed pages, which the kernel may drop and fault back in
    line = next(l for l in Path("/proc/self/status").read_text().splitlines()
                if l.startswith("RssAnon:"))
    return int(line.split()[1]) / 1024

run("cotan", "sphere", 1)
base, seen = anonymous_mb(), []
result, _ = run("cotan", "sphere", 5, observers=[lambda flow: seen.append(anonymous_mb())])
print(json.dumps([result.nV, result.N, max(seen) - base, result.cpu_seconds]))
"""


def test_the_estimate_has_the_order_of_magnitude_of_a_measured_run():
    """Level 5 of the sphere with cotan in a fresh process (its anonymous memory
    above the warmed-up process, sampled at every step, and its CPU time) against
    the fit."""
    root = Path(__file__).resolve().parents[3]
    out = subprocess.run([sys.executable, "-c", MEASURE], cwd=root, check=True, text=True,
                         capture_output=True, env={**os.environ, "PYTHONPATH": str(root)})
    n, steps, memory, seconds = json.loads(out.stdout)
    estimate = cost.estimate(get_scheme("cotan"), n, steps)
    assert 1 / 3 < (estimate.memory_mb - cost.FIXED_MB) / memory < 3, (estimate, memory)
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
    ("bgn@bdf2", "bgn"), ("kll@bdf3", "kll")])
def test_cost_class(scheme, kind):
    assert cost.cost_class(scheme) == kind
