import numpy as np

from ddfv.convergence import space_convergence, time_convergence


def test_time_convergence_is_first_order():
    table = time_convergence(2, [0.01, 0.005, 0.0025], reference_factor=16)
    assert (table.status == "ok").all()
    assert np.all(np.abs(table.eoc[1:] - 1) < 0.15), table.eoc.tolist()
    assert table.l2_error.is_monotonic_decreasing


def test_space_convergence_is_second_order():
    table = space_convergence([2, 3], 0.04 / 4**4)
    assert (table.status == "ok").all()
    assert 1.8 < table.eoc[1] < 2.3, table.eoc.tolist()
