"""The suite's own gallery meshes written as OBJ (:func:`write_generated_mesh`; the
gallery's runs are specs in the run store, :func:`mcfbench.studies.gallery.plan.gallery_specs`)."""

import numpy as np


def obj_text(vertices, faces):
    """A triangle mesh as Wavefront OBJ text (17 significant digits)."""
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in np.asarray(vertices, float).tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in np.asarray(faces, int).tolist()]
    return "\n".join(lines) + "\n"


def write_obj(path, vertices, faces):
    """A triangle mesh as Wavefront OBJ (atomic)."""
    from mcfbench.storage.atomic import write_text

    write_text(path, obj_text(vertices, faces))


def write_generated_mesh(entry, path):
    """Write one mesh of :func:`generated_meshes` (``entry`` = its value):
    :func:`generated_mesh_text`, atomically."""
    from mcfbench.storage.atomic import write_text

    write_text(path, generated_mesh_text(entry))


def generated_mesh_text(entry):
    """The OBJ text of one mesh of :func:`generated_meshes` (``entry`` = its value). A
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
    return obj_text(V, F)
