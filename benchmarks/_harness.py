"""Helpers shared by ``bench_sphere.py`` and ``bench_level6.py`` (not a benchmark).

* :func:`one_core`: pin this process (and so its children) to one core;
  the scripts set the BLAS thread variables themselves, before numpy is
  imported, and call :func:`mcfbench.storage.memory.tune_malloc` first.
* :func:`harness_run`: :func:`mcfbench.running.run.run` exactly as the command
  line runs it, keeping the flow so that its ``timings`` can be read.
* :class:`OldWorker`: the previous numpy implementation (commit ``6cc720c``,
  ``git archive`` into a temporary directory, :func:`extract`) in a persistent
  child process (:class:`Child`): ``worker.run(level)`` times its
  ``ddfv.sphere.sphere_run(level)``.
* :func:`footing`: the caveat printed under every table of timings.
"""

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
                    "NUMBA_NUM_THREADS")



def footing(method="bicgstab", rtol=1e-9):
    """The caveat printed under every table of timings."""
    return (f"Timings between schemes are only fair on the same footing: same solver "
            f"({method}), same rtol ({rtol:g}), compiled kernels for every scheme, one core, "
            f"one BLAS thread, JIT excluded; DDFV has about 3x the unknowns "
            f"(n_F + n_T = 3 n_F) of the vertex schemes (n_F).")


def one_core():
    """Pin this process to the first core it may use; returns that core (or None)."""
    if not hasattr(os, "sched_setaffinity"):
        return None
    core = sorted(os.sched_getaffinity(0))[0]
    os.sched_setaffinity(0, {core})
    return core


def load_average():
    """``"a b c"`` of ``/proc/loadavg`` (1, 5, 15 min), or ``"?"``."""
    try:
        return "%.2f %.2f %.2f" % os.getloadavg()
    except OSError:
        return "?"


def machine_line():
    return (f"{time.strftime('%Y-%m-%d %H:%M')}, {os.cpu_count()} cores, load average "
            f"{load_average()} (1/5/15 min), pinned to core "
            f"{sorted(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else '?'}")


class _Capture:
    """A registry scheme whose ``make`` keeps the flow it built (for ``timings``)."""

    def __init__(self, scheme):
        from mcfbench.running.schemes import get_scheme

        self._scheme = get_scheme(scheme) if isinstance(scheme, str) else scheme
        self.flow = None

    def __getattr__(self, name):
        return getattr(self._scheme, name)

    def make(self, *args, **kwargs):
        self.flow = self._scheme.make(*args, **kwargs)
        return self.flow


def harness_run(scheme, level, *, problem="sphere", solver=None, steps=None, **options):
    """:func:`mcfbench.running.run.run` of ``scheme`` on ``problem`` at ``level``.

    ``steps`` (optional) stops after that many steps (``t_final = steps tau``,
    for smoke tests). Returns ``(result, flow)``: the run's
    :class:`~mcfbench.storage.records.RunResult` and the flow it stepped.
    """
    from mcfbench.running.problems import get_problem
    from mcfbench.running.run import run
    from mcfbench.running.solver import Solver

    capture = _Capture(scheme)
    t_final = None
    if steps is not None:
        t_final = int(steps) * get_problem(problem).tau(level)
    result, _ = run(capture, problem, level, solver=Solver() if solver is None else solver,
                    t_final=t_final, **options)
    return result, capture.flow


def split(result, flow):
    """Seconds of the run by phase: ``geometry`` (DDFV), ``assembly``, ``solve``, ``other``."""
    timings = dict(getattr(flow, "timings", {}))
    phases = {k: timings.get(k, float("nan")) for k in ("geometry", "assembly", "solve")}
    phases["other"] = result.wall_seconds - sum(v for v in phases.values() if v == v)
    return phases


def median(values):
    values = [v for v in values if v == v]
    return statistics.median(values) if values else float("nan")


# --- the previous numpy implementation ------------------------------------------------

OLD_REV = "6cc720c"

_WORKER = r'''
import json, os, sys, time
from ddfv.sphere import sphere_run          # ddfv/__init__ tunes malloc on import
import ddfv
print(json.dumps({"ready": ddfv.__file__}), flush=True)
sphere_run(1)                               # warm-up (imports, first calls)
for line in sys.stdin:
    level = int(line)
    r = sphere_run(level)
    print(json.dumps({"level": level, "wall": r.wall_seconds, "cpu": r.cpu_seconds,
                      "iterations": r.iterations, "l2_error": r.l2_error,
                      "status": r.status, "nV": r.nV, "N": r.N}), flush=True)
'''


def extract(rev, tree, *paths):
    """``git archive rev [paths]`` of this repository unpacked into the directory ``tree``."""
    archive = subprocess.run(["git", "archive", rev, *paths], cwd=ROOT, capture_output=True,
                             check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(tree)], input=archive, check=True)


class Child:
    """A persistent child process of this interpreter (pinned like this one) running the
    Python source ``script`` with ``args`` in the tree ``tree`` (its working directory
    and ``PYTHONPATH``). The script prints one JSON line ``{"ready": ddfv.__file__}``
    when warmed up (checked to be the tree's), then answers every request line with
    one JSON line (:meth:`ask`)."""

    def __init__(self, tree, script, args=()):
        self.tree = str(tree)
        self._proc = subprocess.Popen([sys.executable, "-c", script, *map(str, args)],
                                      cwd=self.tree, env={**os.environ, "PYTHONPATH": self.tree},
                                      stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        ready = json.loads(self._proc.stdout.readline())["ready"]
        if not ready.startswith(self.tree):
            raise RuntimeError(f"the child in {self.tree} imported {ready}")

    def ask(self, request):
        """The child's answer (a dict) to one request line."""
        self._proc.stdin.write(f"{request}\n")
        self._proc.stdin.flush()
        line = self._proc.stdout.readline()
        if not line:
            raise RuntimeError(f"the child in {self.tree} died at {request!r}")
        return json.loads(line)

    def close(self):
        if self._proc.poll() is None:
            self._proc.stdin.close()
            self._proc.wait(timeout=60)


class OldWorker:
    """The implementation at ``rev`` in a :class:`Child` (``git archive`` into a
    temporary directory).

    ``run(level)`` returns ``{"wall", "cpu", "iterations", "l2_error", ...}``
    of its ``ddfv.sphere.sphere_run(level)``: flow construction, every step,
    the error (3.2) and the T monitor, as measured by that function.
    """

    def __init__(self, rev=OLD_REV):
        self.rev = rev
        self._tmp = tempfile.TemporaryDirectory(prefix=f"ddfv-{rev}-")
        extract(rev, self._tmp.name)
        self._child = Child(self._tmp.name, _WORKER)

    def run(self, level):
        return self._child.ask(int(level))

    def close(self):
        self._child.close()
        self._tmp.cleanup()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
