"""Real triangle meshes (scanned, CAD, modelled) shipped inside pinned registry packages.

The suite commits no third-party mesh file: each mesh here is a file of an
installed package (a dependency in ``pyproject.toml``, pinned in
``constraints.txt``), found through :mod:`importlib.metadata` without
importing the package, checked against its SHA-256 and read by
:func:`mcfbench.geometry.mesh_files.read_mesh`. The gallery
(:mod:`mcfbench.studies.gallery`) runs them by default beside the suite's own
meshes. Sources, licences and the reasons for each choice: the "Real meshes"
section of ``results/README.md``.
"""

import base64
import gzip
import hashlib
import importlib.metadata
import tempfile
import xml.etree.ElementTree as ET
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mcfbench.geometry.mesh_files import read_mesh


@dataclass(frozen=True)
class PackagedMesh:
    """One mesh file inside a registry package, and what the intake makes of it.

    Attributes
    ----------
    name : str
        Gallery name (``results/gallery/meshes/{name}.obj``).
    package, version : str
        The distribution and the version pinned in ``constraints.txt``.
    path : str
        The file inside the distribution (relative to site-packages).
    sha256 : str
        Of the file's bytes in that version.
    kind : str
        ``scan``, ``CAD`` or ``modelled``.
    origin, licence : str
        Where the model comes from; the package's licence and the model's terms.
    vertices, triangles, components, boundary_loops, genus : int
        After :func:`read_mesh` (``genus`` of every component).
    """

    name: str
    package: str
    version: str
    path: str
    sha256: str
    kind: str
    origin: str
    licence: str
    vertices: int
    triangles: int
    components: int
    boundary_loops: int
    genus: int


PACKAGED_MESHES = {m.name: m for m in (
    PackagedMesh(
        "nut", "pyvista", "0.49.1", "pyvista/examples/nut.ply",
        "51df5ca42ddbac9123e59678d532557278b11dee915274c98ea8897acc604c0a", "CAD",
        "PyVista's built-in example nut (examples.load_nut): an octagonal nut, "
        "no thread", "MIT (PyVista)", 523, 1046, 1, 0, 1),
    PackagedMesh(
        "ant", "pyvista", "0.49.1", "pyvista/examples/ant.ply",
        "1e825c23c85588c9ea8d31b53e09791a6cd20fa9f835e98d4c61389e4209a73b", "modelled",
        "PyVista's built-in ant (examples.load_ant), the ant of Greg Turk's PLY "
        "sample files", "MIT (PyVista); the PLY samples state no licence of their own",
        486, 912, 15, 0, 0),
    PackagedMesh(
        "brain", "nilearn", "0.13.1", "nilearn/datasets/data/fsaverage5/pial_left.gii.gz",
        "1e76fe43ac194c15fd272643f7ae7995621e2a496b3102b2d6175f0f8e6d7fc8", "scan",
        "nilearn's fsaverage5 left pial surface (GIFTI): FreeSurfer's fsaverage, the "
        "cortex of an average of 40 subjects' MRI scans, on the 5-times subdivided "
        "icosahedron", "BSD-3-Clause (nilearn); fsaverage is FreeSurfer's, under the "
        "FreeSurfer Software License", 10242, 20480, 1, 0, 0),
)}
"""The packaged meshes by gallery name."""


def installed_packaged_meshes():
    """The names of :data:`PACKAGED_MESHES` whose package is installed (the
    extra ``meshes``: ``pip install -e ".[meshes]"``), and those whose is not."""
    installed, missing = [], []
    for name, mesh in PACKAGED_MESHES.items():
        try:
            importlib.metadata.distribution(mesh.package)
            installed.append(name)
        except importlib.metadata.PackageNotFoundError:
            missing.append(name)
    return installed, missing


def packaged_mesh_file(name):
    """The installed file of :data:`PACKAGED_MESHES` ``[name]``, checked.

    Raises
    ------
    FileNotFoundError
        The package is not installed or has no such file.
    ValueError
        The file's SHA-256 differs from the recorded one (another version).
    """
    mesh = PACKAGED_MESHES[name]
    pin = f"{mesh.package}=={mesh.version}"
    try:
        dist = importlib.metadata.distribution(mesh.package)
    except importlib.metadata.PackageNotFoundError:
        raise FileNotFoundError(f"packaged mesh {name!r}: the package {mesh.package} is not "
                                f"installed (install {pin}, pinned in constraints.txt)") from None
    path = Path(dist.locate_file(mesh.path))
    if not path.is_file():
        raise FileNotFoundError(f"packaged mesh {name!r}: {mesh.package} {dist.version} has no "
                                f"file {mesh.path} (expected {pin})")
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    if digest != mesh.sha256:
        raise ValueError(f"packaged mesh {name!r}: {path} of {mesh.package} {dist.version} has "
                         f"SHA-256 {digest}, not the recorded {mesh.sha256} of {pin}")
    return path


def read_packaged_mesh(name):
    """``(V, F, report)`` of a packaged mesh through :func:`read_mesh`. A GIFTI
    surface (``.gii`` or ``.gii.gz``, which libigl cannot read) is first
    converted to a temporary OBJ (vertices and triangles as stored), so every
    packaged mesh goes through the same intake and validation."""
    path = packaged_mesh_file(name)
    if not path.name.endswith((".gii", ".gii.gz")):
        return read_mesh(path)
    V, F = gifti_surface(path)
    with tempfile.TemporaryDirectory() as tmp:
        obj = Path(tmp) / f"{name}.obj"
        lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in V.tolist()]
        lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in F.tolist()]
        obj.write_text("\n".join(lines) + "\n")
        return read_mesh(obj)


_GIFTI_TYPES = {"NIFTI_TYPE_FLOAT32": "f4", "NIFTI_TYPE_FLOAT64": "f8",
                "NIFTI_TYPE_INT32": "i4", "NIFTI_TYPE_UINT8": "u1"}


def gifti_surface(path):
    """``(V, F)`` of a GIFTI surface file (gzipped or not): its
    ``NIFTI_INTENT_POINTSET`` and ``NIFTI_INTENT_TRIANGLE`` arrays, encoded
    ``ASCII``, ``Base64Binary`` or ``GZipBase64Binary``; ``ValueError`` naming
    the file otherwise."""
    path = Path(path)
    opener = gzip.open if path.suffix == ".gz" else open
    with opener(path, "rb") as f:
        root = ET.parse(f).getroot()
    arrays = {}
    for node in root.iter("DataArray"):
        a = node.attrib
        kind, dims = a.get("DataType"), [int(a[f"Dim{i}"]) for i in range(int(a["Dimensionality"]))]
        text = node.findtext("Data") or ""
        if kind not in _GIFTI_TYPES:
            raise ValueError(f"{path}: GIFTI data type {kind} is not supported")
        dtype = np.dtype(_GIFTI_TYPES[kind]).newbyteorder(
            "<" if a.get("Endian", "LittleEndian") == "LittleEndian" else ">")
        if a.get("Encoding") == "ASCII":
            data = np.array(text.split(), dtype=dtype)
        elif a.get("Encoding") in ("Base64Binary", "GZipBase64Binary"):
            raw = base64.b64decode(text)
            raw = zlib.decompress(raw) if a["Encoding"] == "GZipBase64Binary" else raw
            data = np.frombuffer(raw, dtype=dtype)
        else:
            raise ValueError(f"{path}: GIFTI encoding {a.get('Encoding')} is not supported")
        order = "F" if a.get("ArrayIndexingOrder") == "ColumnMajorOrder" else "C"
        arrays[a.get("Intent")] = data.reshape(dims, order=order)
    try:
        V, F = arrays["NIFTI_INTENT_POINTSET"], arrays["NIFTI_INTENT_TRIANGLE"]
    except KeyError as err:
        raise ValueError(f"{path}: no GIFTI array of intent {err.args[0]}") from None
    return np.asarray(V, float), np.asarray(F, np.int64)
