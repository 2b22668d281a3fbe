"""Threads of the compiled kernels: a kernel's ``parallel=True`` copy
(:func:`threaded`), the choice between the two (:func:`for_threads`) and the
check of a thread count (:func:`check_threads`).

Apart from :mod:`ddfv.kernels`, which compiles (or loads from numba's cache)
every DDFV kernel when imported: the shared solver of the harness and the
baselines' runs check and use threads without paying for the DDFV kernels.
"""

import functools
import types

import numba
import numpy as np


@functools.cache
def threaded(kernel, **callees):
    """``kernel`` compiled again with ``parallel=True``: its ``prange`` loops are
    split into one block of iterations per thread, their sums and minima
    reduced per block.

    One source for both versions. The copy has its own name, hence its own
    entry in numba's cache; it is built and compiled on first use, so a
    one-thread run never compiles it. ``callees`` replace the compiled
    functions the kernel calls, by name (their threaded copies); numba's
    cache does not key on them, so each kernel has one set of callees (one
    call site).

    Parameters
    ----------
    kernel : numba dispatcher
    **callees : numba dispatchers

    Returns
    -------
    numba dispatcher
        Compiled lazily for the argument types of each call.
    """
    py = kernel.py_func
    clone = types.FunctionType(py.__code__, {**py.__globals__, **callees},
                               f"{py.__name__}_threaded", py.__defaults__, py.__closure__)
    clone.__qualname__, clone.__doc__ = clone.__name__, py.__doc__
    options = {k: v for k, v in kernel.targetoptions.items() if k != "nopython"}
    return numba.njit(parallel=True, cache=True, **options)(clone)


def check_threads(threads):
    """Refuse a thread count that is not a whole number in ``[1, NUMBA_NUM_THREADS]``."""
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) \
            or threads < 1:
        raise ValueError(f"threads must be a whole number >= 1, got {threads!r}")
    if threads > numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"threads={threads} exceeds the {numba.config.NUMBA_NUM_THREADS} "
                         "thread(s) numba was started with (NUMBA_NUM_THREADS, by default "
                         "the number of cores)")


def for_threads(kernel, threads, **callees):
    """``kernel`` for one thread; else its :func:`threaded` copy (calling the
    threaded copies of ``callees``), with numba set to ``threads`` threads.

    Raises
    ------
    ValueError
        ``threads`` is not a whole number in ``[1, NUMBA_NUM_THREADS]``.
    """
    check_threads(threads)
    if threads == 1:
        return kernel
    numba.set_num_threads(threads)
    return threaded(kernel, **{name: threaded(c) for name, c in callees.items()})
