"""Real triangle meshes committed as data under ``mcfbench/data/meshes/``.

Public closed surfaces with a permissive licence (CAD parts, modelled
characters), each a
file of that folder described by one entry of its ``manifest.json``: the
source repository, path and commit, the author, the licence, the kind, the
counts, Euler characteristic and genus after the intake, the processing done
and the file's SHA-256. The folder's ``README.md`` is the table of the same
entries for readers. Every file reads through the one intake
(:func:`mcfbench.geometry.mesh_files.read_mesh`), after its SHA-256 is checked,
so a corrupted or replaced file is refused by name. :func:`real_mesh` is
the surface generator ``real_mesh`` of :mod:`mcfbench.geometry.surfaces`: a
level of the mesh's Loop-limit series.

The raw corpus ``mcfbench/data/raw_meshes/`` (:data:`RAW_DIR`) is a second
folder of the same kind for the survival study (issue #44): public meshes as
they come and generated defects of the committed ones, with no reference
answer, listed by :func:`raw_manifest` (the same provenance fields, plus the
intake's outcome, the topology and quality measured, and the thin-feature
criterion of :mod:`mcfbench.geometry.thickness`). A member may be a file the
intake refuses (a non-manifold edge, say): :func:`read_raw_mesh` then raises
the intake's :class:`mcfbench.geometry.mesh.MeshError`, whose ``kind`` the
manifest names as the member's ``defect``.
"""

import functools
import hashlib
import json
from pathlib import Path


MESH_DIR = Path(__file__).resolve().parents[1] / "data" / "meshes"
"""The folder of the committed meshes, their manifest and README."""

RAW_DIR = MESH_DIR.parent / "raw_meshes"
"""The folder of the raw corpus, its manifest and README."""


@functools.cache
def mesh_manifest():
    """The entries of ``manifest.json``: name -> dict (``file``, ``sha256``,
    ``repository``, ``path``, ``commit``, ``author``, ``licence``, ``kind``,
    ``vertices``, ``faces``, ``euler_characteristic``, ``genus``,
    ``thin_features``, ``processing``)."""
    return json.loads((MESH_DIR / "manifest.json").read_text())


def committed_mesh_file(name):
    """The file of the committed mesh ``name``, its SHA-256 checked.

    Raises
    ------
    ValueError
        Unknown name (listing the known ones), or the file's SHA-256 differs
        from the manifest's (a corrupted or replaced file).
    """
    return _checked_file(MESH_DIR, mesh_manifest(), name, "committed mesh")


def _checked_file(folder, manifest, name, what):
    if name not in manifest:
        raise ValueError(f"unknown {what} {name!r}; choose one of {', '.join(manifest)}")
    entry = manifest[name]
    path = folder / entry["file"]
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != entry["sha256"]:
        raise ValueError(f"{what} {name!r}: {path} has SHA-256 {digest}, not the "
                         f"manifest's {entry['sha256']} (corrupted or replaced file)")
    return path


def read_committed_mesh(name):
    """``(V, F)`` of the committed mesh ``name`` through :func:`read_mesh`
    (a ``(n, 3)`` float64 and an ``(m, 3)`` int64 array, a valid surface)."""
    from mcfbench.geometry.mesh_files import read_mesh  # libigl: on first use, not the registry's

    V, F, _ = read_mesh(committed_mesh_file(name))
    return V, F


def real_mesh(mesh="nut", level=0):
    """Level ``level`` of the Loop-limit refinement series of the committed mesh
    named ``mesh`` (default the smallest, ``nut``;
    :func:`mcfbench.geometry.subdivision.loop_limit_level`): ``(V, F)``."""
    from mcfbench.geometry.subdivision import loop_limit_level

    return loop_limit_level(*read_committed_mesh(mesh), level)


@functools.cache
def raw_manifest():
    """The entries of the raw corpus's ``manifest.json``: name -> dict. Every
    entry has ``file``, ``sha256``, ``bytes``, ``origin`` (``raw``: the source's
    mesh as it comes; ``generated``: made from a committed mesh, said in
    ``processing``), ``repository``, ``path``, ``commit``, ``author``,
    ``licence``, ``kind``, ``processing``, ``intake`` (``read`` or ``refused``)
    and ``defect`` (the intake's :class:`~mcfbench.geometry.mesh.MeshError`
    kind if refused, else empty); a file that reads also has ``repairs`` (the
    intake's notes), ``file_vertices``, ``file_faces``, ``vertices``,
    ``faces``, ``components``, ``boundary_loops``, ``genus`` (the sorted
    distinct genera of its components), ``smallest_angle`` (degrees),
    ``area_ratio``, ``mean_edge``, ``thin_share``, ``thin_features`` and
    ``traits``."""
    return json.loads((RAW_DIR / "manifest.json").read_text())


def raw_mesh_file(name):
    """The file of the raw corpus's member ``name``, its SHA-256 checked
    (``ValueError`` as :func:`committed_mesh_file`)."""
    return _checked_file(RAW_DIR, raw_manifest(), name, "raw mesh")


def read_raw_mesh(name):
    """``(V, F, report)`` of the raw member ``name`` through :func:`read_mesh`.

    Raises
    ------
    mcfbench.geometry.mesh.MeshError
        The intake refuses the file (the manifest's ``defect`` names its kind).
    """
    from mcfbench.geometry.mesh_files import read_mesh

    return read_mesh(raw_mesh_file(name))
