"""Threads of the compiled kernels: a kernel's parallel copy (:func:`threaded`), the
choice between the two (:func:`for_threads`) and the check of a thread count
(:func:`check_threads`).

Below both scheme packages (``ddfv`` and ``baselines`` may not import each other) and
the harness's solver, which all thread their kernels with it. Imports numba and numpy
only (no scheme's kernels: a vertex scheme's run does not load DDFV's).
"""

import functools
import types

import numba
import numpy as np
from numba.core.cpu import ParallelOptions

PRANGE_ONLY = {"prange": True, "comprehension": False, "reduction": False,
               "inplace_binop": False, "setitem": False, "numpy": False, "stencil": False,
               "fusion": False}
"""numba's ``parallel`` options of a threaded copy: its ``prange`` loops only. With
``parallel=True`` numba also turns array expressions and slice assignments into
parallel regions, wherever they are: the solver's residual zeroes three small arrays
per row of a coupled system (``ax[:] = 0.0``), and BGN's two-thread step opened three
regions per row of its 3n rows (level 7: 622 ms against 54 ms on one thread, idle
machine; level 5 under load: a residual 1.3 s against 1.3 ms)."""


@functools.cache
def threaded(kernel, **callees):
    """``kernel`` compiled again with its ``prange`` loops parallel
    (:data:`PRANGE_ONLY`): each split into one block of iterations per thread,
    their sums and minima reduced per block.

    One source for both versions. The copy has its own name (``NAME_prange``),
    hence its own entry in numba's cache (whose index does not key on the
    compile options); it is built and compiled on first use, so a
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
                               f"{py.__name__}_prange", py.__defaults__, py.__closure__)
    clone.__qualname__, clone.__doc__ = clone.__name__, py.__doc__
    options = {k: v for k, v in kernel.targetoptions.items() if k != "nopython"}
    # not the dict itself: numba pops the keys of a dict of options at each compilation,
    # and a second one (other argument types) from the emptied dict has every option on;
    # a kernel without a prange loop of its own (the solver's iteration, which calls the
    # threaded products) is compiled serial: parallel would find nothing, and warn
    parallel = (ParallelOptions(dict(PRANGE_ONLY)) if "prange" in py.__code__.co_names
                else False)
    return numba.njit(parallel=parallel, cache=True, **options)(clone)


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
