"""Acceptance: Table 3.1 of the paper (Section 3.1), mcfbench/studies/convergence/ (job.sphere_table, tables)."""

import numpy as np
import pytest

from mcfbench.running.problems import get_problem
from mcfbench.running.run import run
from mcfbench.running.solver import Solver
from mcfbench.studies.convergence.job import sphere_table
from mcfbench.studies.convergence.tables import PUBLISHED


def sphere_run(level, scheme="ddfv", rtol=1e-9, **options):
    """One row of Table 3.1 for ``scheme`` (flat dict, ``l2_error`` included)."""
    result, _ = run(scheme, "sphere", level, solver=Solver(rtol=rtol), **options)
    return result


@pytest.fixture(scope="module")
def table():
    return sphere_table([1, 2, 3, 4, 5])


def test_table_3_1_l2_errors_reproduced(table):
    assert (table["status"] == "ok").all()
    ratio = table.set_index("level")["l2_ratio"]
    assert abs(ratio[1] - 1) < 0.03
    for level in (2, 3, 4, 5):
        assert abs(ratio[level] - 1) < 0.01, (level, ratio[level])


def test_table_3_1_orders_reproduced(table):
    t = table.set_index("level")
    for level in (2, 3, 4, 5):
        assert abs(t.eoc[level] - t.paper_eoc[level]) < 0.03, level


def test_table_3_1_discretisation(table):
    for row in table.itertuples():
        nV, nF, nT, tau, N = PUBLISHED[row.level][:5]
        assert (row.nV, row.nF, row.nT, row.N) == (nV, nF, nT, N)
        assert row.tau == pytest.approx(tau)
        assert 0.2 < row.t_min_barycentric <= 1 / 3


@pytest.mark.parametrize("t_init", ["exact", "barycenter"])
def test_second_order_for_every_t_initialisation(t_init):
    errors = [sphere_run(level, t_init=t_init).metrics["l2_error"] for level in (1, 2, 3)]
    orders = np.log2(np.array(errors[:-1]) / errors[1:])
    assert np.all((orders > 1.75) & (orders < 2.2)), orders


def test_tolerance_default_is_converged():
    """Tightening rtol 1000x changes the level-3 error by < 0.01 %."""
    default, tight = sphere_run(3), sphere_run(3, rtol=1e-12)
    assert default.metrics["l2_error"] == pytest.approx(tight.metrics["l2_error"], rel=1e-4)
    assert tight.iterations > default.iterations


def test_warm_start_previous_reproduces_published_iteration_counts():
    """With x0 = X^{n-1} and rtol = 1e-8 the counts are within 25 % of the paper's."""
    for level in (2, 3, 4):
        run = sphere_run(level, warm_start="previous", rtol=1e-8)
        assert run.iterations == pytest.approx(PUBLISHED[level][6], rel=0.25)


def test_time_step_coupling():
    sphere = get_problem("sphere")
    assert [sphere.tau(k) for k in (1, 2, 5)] == [0.04, 0.01, 0.04 / 256]
    with pytest.raises(ValueError, match="not a whole multiple of tau = 0.03"):
        sphere_run(1, tau=0.03)


@pytest.mark.parametrize("scheme", ["ddfv-chord", "ddfv-eliminate", "ddfv-chord-eliminate"])
def test_variants_converge_at_second_order_and_are_recorded(scheme):
    runs = [sphere_run(level, scheme) for level in (1, 2, 3)]
    assert all(r.scheme == scheme and r.status == "ok" for r in runs)
    errors = np.array([r.metrics["l2_error"] for r in runs])
    orders = np.log2(errors[:-1] / errors[1:])
    assert np.all((orders > 1.8) & (orders < 2.2)), (scheme, orders)


def test_unknown_scheme_is_named():
    with pytest.raises(ValueError, match="unknown scheme 'fast'; choose one of ddfv, "):
        sphere_run(1, "fast")


def test_integrators_key_adds_the_bdf2_rows_of_every_scheme():
    from mcfbench.studies.convergence.plan import plan

    config = {"levels": [1, 2], "schemes": ["ddfv", "cotan"], "rtol": 1e-9,
              "tau_level_1": 0.04, "t_final": 0.08}
    assert plan(config)["schemes"] == ["ddfv", "cotan"]
    both = plan({**config, "integrators": ["euler", "bdf2"]})
    assert both["schemes"] == ["ddfv", "cotan", "ddfv@bdf2", "cotan@bdf2"]
