"""Keep freed memory in the process instead of returning it to the kernel.

Every time step allocates temporaries of a few MB. With glibc's defaults
such blocks are mapped fresh and trimmed again at every free, so each step
pays for hundreds of page faults (transparent huge pages make each one
expensive): on the level-5 sphere this doubled the wall time, 44 % of it in
the kernel. Raising glibc's mmap and trim thresholds lets the heap recycle
the blocks. Process-wide, so never done on import: the entry points (the
command line, the pipeline's jobs, the benchmarks) call :func:`tune_malloc`.
A no-op elsewhere than glibc; ``DDFV_MALLOC_TUNING=0`` leaves the allocator
alone.

:func:`peak_rss_mb` is the peak resident memory of the process, stored in
every run record (:func:`mcfbench.storage.records.write_record`);
:func:`resident_mb` its resident memory now, :func:`available_mb` the
machine's available memory (the size guard, :mod:`mcfbench.running.cost`).
"""

import ctypes
import ctypes.util
import os
import sys
from pathlib import Path

_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD = 32 * 2**20   # glibc's maximum
TRIM_THRESHOLD = 256 * 2**20


def tune_malloc():
    """Raise glibc's mmap and trim thresholds; return whether it was done."""
    if os.environ.get("DDFV_MALLOC_TUNING", "1") == "0":
        return False
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c"))
        mallopt = libc.mallopt
    except (OSError, AttributeError, TypeError):
        return False
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)
                and mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD))


def peak_rss_mb():
    """Peak resident memory of this process so far, in MB (2**20 bytes).

    ``getrusage(RUSAGE_SELF).ru_maxrss`` (kilobytes on Linux, bytes on
    macOS): for a pipeline job, which writes its one record at its end, the
    peak of the whole job (imports and compilation included). NaN where the
    ``resource`` module does not exist (Windows).
    """
    try:
        import resource
    except ImportError:
        return float("nan")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (2**20 if sys.platform == "darwin" else 2**10)


def resident_mb():
    """Resident memory of this process now (``/proc/self/statm``), in MB; NaN where
    that file does not exist."""
    try:
        pages = int(Path("/proc/self/statm").read_text().split()[1])
    except OSError:
        return float("nan")
    return pages * os.sysconf("SC_PAGE_SIZE") / 2**20


MEMINFO = Path("/proc/meminfo")


def available_mb():
    """Memory the machine has available for new allocations without swapping
    (``MemAvailable`` of :data:`MEMINFO`), in MB; None where it is not known."""
    try:
        text = MEMINFO.read_text()
    except OSError:
        return None
    for line in text.splitlines():
        if line.startswith("MemAvailable:"):
            return int(line.split()[1]) / 2**10           # kB
    return None
