"""Time the compiled per-step kernels against the numpy versions they replaced.

For each icosphere level, prints the time per step (ms) and per diamond (ns)
of ``diamond_geometry``, ``covolume_areas``, ``Assembler.system``,
``t_barycentric``, ``vertex_normals`` (elimination (3.6) only) and of one
step's geometry and assembly (the first four together), for the compiled
kernels of ``ddfv`` ("new") and for the numpy implementations of commit
``6cc720c`` ("old", extracted with ``git show`` into a temporary package).
Old and new run in this one process, interleaved in rounds, and the minimum
over rounds is reported: the machine is shared and noisy, so compare the
ratios, not the absolute times. The coordinates are strided views of one
``(3, n_F + n_T)`` array, as in :class:`ddfv.Flow`.

Then the JIT costs, each in a fresh interpreter: ``import ddfv``, numba's
import, compiling the kernels into an empty cache (``NUMBA_CACHE_DIR`` in
a temporary directory) and loading them from that cache.

    python benchmarks/bench_kernels.py [--levels 3 4 5] [--rounds 15]
        [--rev 6cc720c] [--no-jit]
"""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"          # before numpy is imported

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from ddfv import assembly, geometry  # noqa: E402
from ddfv.topology import diamond_mesh  # noqa: E402


def numpy_reference(rev, tmp):
    """``geometry`` and ``assembly`` of ``ddfv`` at git revision ``rev``."""
    modules = []
    for name in ("geometry", "assembly"):
        path = Path(tmp) / f"ddfv_numpy_{name}.py"
        path.write_text(subprocess.run(["git", "show", f"{rev}:ddfv/{name}.py"], cwd=ROOT,
                                       capture_output=True, text=True, check=True).stdout)
        spec = importlib.util.spec_from_file_location(path.stem, path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        modules.append(module)
    return modules


def icosphere(level):
    """The icosphere of Table 3.1 (the harness's generator if there is one)."""
    try:
        from mcfbench.geometry.spheres import icosphere as harness_icosphere
        return harness_icosphere(level)
    except ImportError:
        pass
    g = (1 + 5**0.5) / 2
    V = np.array([[-1, g, 0], [1, g, 0], [-1, -g, 0], [1, -g, 0], [0, -1, g], [0, 1, g],
                  [0, -1, -g], [0, 1, -g], [g, 0, -1], [g, 0, 1], [-g, 0, -1], [-g, 0, 1]])
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9],
                  [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2],
                  [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
                  [8, 6, 7], [9, 8, 1]])
    V = V / np.linalg.norm(V, axis=1, keepdims=True)
    for _ in range(level):
        mesh = diamond_mesh(F, len(V))
        mid = len(V) + mesh.halfedges
        (v0, v1, v2), (m01, m12, m20) = F.T, mid.T
        F = np.concatenate([np.column_stack(c) for c in ((v0, m01, m20), (v1, m12, m01),
                                                          (v2, m20, m12), (m01, m12, m20))])
        a, b = mesh.diamonds[:, 0], mesh.diamonds[:, 1]
        V = np.concatenate([V, 0.5 * (V[a] + V[b])])
        V /= np.linalg.norm(V, axis=1, keepdims=True)
    return V, F


def state(level, seed=0):
    """Mesh and strided ``F, T`` views of one ``(3, n)`` state, as in a flow."""
    V, faces = icosphere(level)
    mesh = diamond_mesh(faces, len(V))
    p0, p1, p2 = V[faces].swapaxes(0, 1)
    h = np.sqrt(0.5 * np.linalg.norm(np.cross(p1 - p0, p2 - p0), axis=1).mean())
    T = (p0 + p1 + p2) / 3 + 0.01 * h * np.random.default_rng(seed).normal(size=p0.shape)
    X = np.ascontiguousarray(np.concatenate([V, T]).T)
    return mesh, X[:, :mesh.n_f].T, X[:, mesh.n_f:].T


def kernels_of(geom_module, assembly_module, mesh, F, T, tau=1e-3):
    """The timed calls of one implementation, sharing one set of inputs."""
    G = geom_module
    asm = assembly_module.Assembler(mesh)
    g = G.diamond_geometry(mesh, F, T)
    chi = np.concatenate(G.covolume_areas(mesh, g))

    def step():
        g = G.diamond_geometry(mesh, F, T)
        asm.system(g, np.concatenate(G.covolume_areas(mesh, g)), tau)
        G.t_barycentric(F, T, mesh.faces)

    return {
        "diamond_geometry": lambda: G.diamond_geometry(mesh, F, T),
        "covolume_areas": lambda: G.covolume_areas(mesh, g),
        "Assembler.system": lambda: asm.system(g, chi, tau),
        "t_barycentric": lambda: G.t_barycentric(F, T, mesh.faces),
        "vertex_normals": lambda: G.vertex_normals(mesh, g),
        "step (first four)": step,
    }


def interleaved(calls, rounds, budget=0.02):
    """Min over ``rounds`` of the mean time of a batch of calls, in seconds."""
    best = {key: np.inf for key in calls}
    batch = {}
    for key, call in calls.items():   # warm-up and batch size (~budget s per batch)
        start = time.perf_counter()
        call()
        batch[key] = max(1, int(budget / max(time.perf_counter() - start, 1e-7)))
    for _ in range(rounds):
        for key, call in calls.items():
            start = time.perf_counter()
            for _ in range(batch[key]):
                call()
            best[key] = min(best[key], (time.perf_counter() - start) / batch[key])
    return best


def max_relative_difference(old, new, mesh, F, T):
    """Largest difference of the old and new outputs, relative to each field;
    the CSR patterns must be identical."""
    out = []
    for G, assembly_module in (old, new):
        g = G.diamond_geometry(mesh, F, T)
        chi = np.concatenate(G.covolume_areas(mesh, g))
        A = assembly_module.Assembler(mesh).system(g, chi, 1e-3)
        out.append([A.indptr, A.indices] + [getattr(g, f) for f in g.__dataclass_fields__]
                   + [chi, A.data, G.t_barycentric(F, T, mesh.faces), G.vertex_normals(mesh, g)])
    (indptr_old, indices_old, *old_values), (indptr_new, indices_new, *new_values) = out
    assert np.array_equal(indptr_old, indptr_new) and np.array_equal(indices_old, indices_new)
    return max(float(np.abs(x - y).max() / np.abs(x).max())
               for x, y in zip(old_values, new_values))


def run_python(code, env=None):
    """Wall time (s) of ``python -c code`` and its last output line."""
    start = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True,
                         text=True, check=True, env=env).stdout
    return time.perf_counter() - start, out.strip().splitlines()[-1] if out.strip() else ""


def jit_costs(repeats=3):
    """Seconds of ``import ddfv``, numba's import, a cold compile and a cached load."""
    timed_import = ("import time; t = time.perf_counter(); import {0}; "
                    "print(time.perf_counter() - t)")
    kernels = ("import time, ddfv, numba; t = time.perf_counter(); import ddfv.kernels; "
               "print(time.perf_counter() - t)")
    rows = {"python -c 'import ddfv' (wall)": [], "import ddfv (in process)": [],
            "import numba (in process)": [], "kernels: compile, empty cache": [],
            "kernels: load from cache": []}
    for _ in range(repeats):
        rows["python -c 'import ddfv' (wall)"].append(run_python("import ddfv")[0])
        rows["import ddfv (in process)"].append(float(run_python(timed_import.format("ddfv"))[1]))
        rows["import numba (in process)"].append(float(run_python(timed_import.format("numba"))[1]))
        with tempfile.TemporaryDirectory() as cache:
            env = dict(os.environ, NUMBA_CACHE_DIR=cache)
            rows["kernels: compile, empty cache"].append(float(run_python(kernels, env)[1]))
            rows["kernels: load from cache"].append(float(run_python(kernels, env)[1]))
    return {key: min(values) for key, values in rows.items()}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--levels", type=int, nargs="+", default=[3, 4, 5])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--rev", default="6cc720c", help="git revision of the numpy versions")
    parser.add_argument("--no-jit", action="store_true", help="skip the JIT start-up costs")
    args = parser.parse_args()
    if hasattr(os, "sched_setaffinity"):
        os.sched_setaffinity(0, {sorted(os.sched_getaffinity(0))[0]})   # one core
    try:
        from mcfbench.storage.memory import tune_malloc
        tuned = tune_malloc()
    except ImportError:
        tuned = False
    print(f"glibc malloc tuning (as in the harness): {'on' if tuned else 'off'}")
    new = (geometry, assembly)
    with tempfile.TemporaryDirectory() as tmp:
        old = numpy_reference(args.rev, tmp)
        for level in args.levels:
            mesh, F, T = state(level)
            n_d = len(mesh.diamonds)
            calls = {}
            for tag, implementation in (("old", old), ("new", new)):
                for key, call in kernels_of(*implementation, mesh, F, T).items():
                    calls[key, tag] = call
            best = interleaved(calls, args.rounds)
            print(f"\nlevel {level}: n_F = {mesh.n_f}, n_T = {mesh.n_t}, n_d = {n_d}; "
                  f"max relative difference old/new "
                  f"{max_relative_difference(old, new, mesh, F, T):.1e}")
            print(f"{'per step':20s} {'old ms':>8s} {'new ms':>8s} {'old ns/d':>9s} "
                  f"{'new ns/d':>9s} {'speed-up':>8s}")
            for key in dict.fromkeys(k for k, _ in calls):
                t_old, t_new = best[key, "old"], best[key, "new"]
                print(f"{key:20s} {1e3 * t_old:8.3f} {1e3 * t_new:8.3f} "
                      f"{1e9 * t_old / n_d:9.1f} {1e9 * t_new / n_d:9.1f} "
                      f"{t_old / t_new:7.2f}x")
    if not args.no_jit:
        print("\nstart-up, seconds (min of 3, each in a fresh interpreter)")
        for key, seconds in jit_costs().items():
            print(f"{key:32s} {seconds:6.2f}")


if __name__ == "__main__":
    main()
