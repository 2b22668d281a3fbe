"""kept_factor.threads: the threaded copy of a kernel, the thread-count check."""

import numba
import numpy as np
import pytest

from kept_factor.threads import PRANGE_ONLY, check_threads, for_threads, threaded


@numba.njit(cache=True)
def _sum_and_shift(x, out):
    """A prange sum and a serial loop with a slice assignment per row (what numba's
    ``parallel=True`` would make one parallel region of, per row)."""
    total = 0.0
    for i in numba.prange(x.shape[0]):
        total += x[i]
    buf = np.empty(2)
    for i in range(x.shape[0]):
        buf[:] = x[i]
        out[i] = buf[0] + buf[1]
    return total


def test_a_threaded_copy_splits_its_prange_loops_only():
    """Only the prange loops are parallel (PRANGE_ONLY): BGN's two-thread solve once
    opened three regions per row in the residual's slice assignments."""
    kernel = threaded(_sum_and_shift)
    assert kernel.targetoptions["parallel"] == PRANGE_ONLY
    assert {k for k, v in PRANGE_ONLY.items() if v} == {"prange"}
    assert kernel.py_func.__name__ == "_sum_and_shift_prange"
    x = np.arange(1.0, 1001.0)
    out = np.empty_like(x)
    assert for_threads(_sum_and_shift, 2)(x, out) == 500500.0
    np.testing.assert_array_equal(out, 2 * x)
    assert for_threads(_sum_and_shift, 1) is _sum_and_shift


@pytest.mark.parametrize("threads", [0, -1, 2.0, True, 10**6])
def test_bad_thread_counts_are_refused(threads):
    with pytest.raises(ValueError, match="threads"):
        check_threads(threads)
