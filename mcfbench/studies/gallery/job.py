"""One scheme on one mesh file of the gallery (:func:`job`), and the suite's own
meshes written as OBJ (:func:`write_generated_mesh`)."""

from pathlib import Path

import numpy as np

from mcfbench.running.run import failed_result, framed_run
from mcfbench.storage.logs import setup_logging
from mcfbench.studies.gallery.plan import MOVIE_FRAMES


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


def job(mesh_path, scheme, settings, record, frames, log_path=None):
    """One scheme on one mesh file: ``tau = C h^2``, ``steps`` steps; record and
    frames (about :data:`MOVIE_FRAMES`, the first and last among them). A file the
    reader refuses gives status ``unsupported`` with the reader's message."""
    from mcfbench.geometry import metrics
    from mcfbench.geometry.mesh_files import read_mesh
    from mcfbench.running.problems import Problem
    from mcfbench.running.schemes import get_scheme
    from mcfbench.running.solver import Solver
    from mcfbench.storage.frames import save_frames
    from mcfbench.storage.records import write_record

    log = setup_logging(log_path)
    solver = Solver.of_settings(settings)
    problem = Problem.user_mesh("a user's mesh", settings["steps"], settings["C"],
                                name="gallery")
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
        result = failed_result(scheme, problem, 1, "unsupported", message,
                               steps=settings["steps"], method=solver.method)
        save_frames(frames, {"faces": np.zeros((0, 3), int), "steps": np.zeros(0, int),
                             "t": np.zeros(0)})
    write_record(record, result, settings, metric_names=[], **extra)
    log.info("%s: %s, %d/%d steps", scheme.name, result.status, result.steps_done, result.N)
    return result
