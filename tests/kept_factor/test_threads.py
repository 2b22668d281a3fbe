"""kept_factor.threads: the threaded copy of a kernel, the thread-count check."""

import numba
import numpy as np
import pytest
from numba.core.cpu import ParallelOptions

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
    """Only the prange loops are parallel (PRANGE_ONLY), for every argument type it is
    compiled for: BGN's two-thread solve once opened three regions per row in the
    residual's slice assignments, and numba empties a dict of options as it compiles."""
    kernel = threaded(_sum_and_shift)
    assert kernel.py_func.__name__ == "_sum_and_shift_prange"
    assert for_threads(_sum_and_shift, 1) is _sum_and_shift
    for dtype in (np.float64, np.float32):           # two compilations
        x = np.arange(1.0, 1001.0, dtype=dtype)
        out = np.empty_like(x)
        assert for_threads(_sum_and_shift, 2)(x, out) == 500500.0
        np.testing.assert_array_equal(out, 2 * x)
        assert kernel.targetoptions["parallel"] == ParallelOptions(dict(PRANGE_ONLY))
    assert {k for k, v in PRANGE_ONLY.items() if v} == {"prange"} and len(PRANGE_ONLY) == 8


@pytest.mark.parametrize("threads", [0, -1, 2.0, True, 10**6])
def test_bad_thread_counts_are_refused(threads):
    with pytest.raises(ValueError, match="threads"):
        check_threads(threads)
