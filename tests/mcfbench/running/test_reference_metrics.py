"""The metrics of the problems with an exact or reference answer (issue: a
reference answer for every problem): the disk's decay rate, the catenoid's
area, the volume before a pinch and the pinch time, each against a value
computed here another way."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import jn_zeros

from mcfbench.geometry.axisymmetric_references import reference_numbers
from mcfbench.geometry.exact import J01_SQUARED, catenoid_area, disk_decay_rate
from mcfbench.geometry.metrics import catenoid_parameter
from mcfbench.running.problems import PROBLEMS, get_problem
from mcfbench.running.run import pinch_time_error, run


def test_decay_rate_of_the_disk_is_the_first_dirichlet_eigenvalue():
    assert J01_SQUARED == pytest.approx(jn_zeros(0, 1)[0] ** 2, rel=1e-15)
    assert disk_decay_rate(2.0) == pytest.approx(J01_SQUARED / 4.0, rel=1e-15)


def test_catenoid_area_by_quadrature():
    a = catenoid_parameter(1.0, 0.5)
    # area of revolution of r(z) = a cosh(z/a): 2 pi int r sqrt(1 + r'^2) dz
    by_quadrature = quad(lambda z: 2 * math.pi * a * math.cosh(z / a) ** 2, -0.5, 0.5,
                         epsabs=1e-14)[0]
    assert catenoid_area(1.0, 0.5) == pytest.approx(by_quadrature, rel=1e-13)


def _flow(V, faces, t):
    return SimpleNamespace(vertices=V, faces=faces, n=round(t / 0.25), tau=0.25, fixed=None)


def test_decay_observer_measures_an_exact_exponential():
    problem = get_problem("hemisphere")
    decay = next(o for o in problem.observers() if type(o).__name__ == "_Decay")
    lam = disk_decay_rate(1.0)
    V = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    for t in (0.75, 1.0, 1.25, 1.5):
        decay(_flow(V * [1, 1, math.exp(-lam * t)], np.array([[0, 1, 2]]), t))
    values = decay.result()
    assert abs(values["decay_rate_error"]) < 1e-12
    assert values["max_height"] == pytest.approx(math.exp(-1.5 * lam), rel=1e-12)


def test_volume_before_the_pinch_survives_a_later_breakdown():
    result, _ = run("cotan", "dumbbell", 1)
    assert result.status != "ok" and result.t_failed > 0.08          # it stops near the pinch
    assert math.isnan(result.metrics["volume"])                       # a final-state metric
    assert abs(result.metrics["volume_error"]) < 0.02                 # sampled at t = 0.08
    assert result.metrics["pinch_time_error"] == pytest.approx(
        result.t_failed / PROBLEMS["dumbbell"].reference["pinch_time"] - 1.0, rel=1e-12)


def test_pinch_time_error_only_for_runs_that_stopped():
    stopped = SimpleNamespace(ok=False, status="inverted", t_failed=0.11, surgeries=[])
    assert pinch_time_error(stopped, 0.1) == pytest.approx(0.1)
    assert math.isnan(pinch_time_error(SimpleNamespace(ok=True, t_failed=math.nan,
                                                       surgeries=[]), 0.1))
    # a tube that vanished round: its extinction time, not the step the run stopped at
    extinct = SimpleNamespace(ok=False, status="extinct", t_failed=0.11,
                              extinction_time=0.115, surgeries=[])
    assert pinch_time_error(extinct, 0.1) == pytest.approx(0.15)
    # a run that cut its neck (NAME+surgery): the first cut's pinch time, whatever its end
    cut = [{"pinch_time": 0.105}, {"pinch_time": 0.2}]
    for end in (extinct, SimpleNamespace(ok=True, t_failed=math.nan)):
        end.surgeries = cut
        assert pinch_time_error(end, 0.1) == pytest.approx(0.05)


def test_registry_references_agree_with_the_meridian_solver():
    """The torus's pinch time and volume, recomputed (the coarse, quick series);
    the dumbbell's take 10 s: benchmarks/axisymmetric_references.py."""
    torus = reference_numbers(("torus",), quick=True)["torus"]
    reference = PROBLEMS["torus"].reference
    T, err = torus["pinch_time"]
    assert abs(T - reference["pinch_time"]) < 3 * err + 1e-9
    k = list(torus["times"]).index(reference["volume_time"])
    volume, volume_err = torus["volume"][0][k], torus["volume"][1][k]
    assert abs(volume - reference["volume"]) < 3 * volume_err + 1e-9
