"""ParaView collections: one ``.vtu`` file per frame and part, listed with its time in a ``.pvd``.

The meshes (points, triangles or vertex cells, point and cell fields) are
written by meshio's VTU writer (binary, zlib). meshio has no writer for the
collection file (ParaView's ``.pvd``: a ``VTKFile`` of type ``Collection``
whose ``DataSet`` elements give ``timestep``, ``part`` and ``file``), so
that small XML file is written here, by :mod:`xml.etree.ElementTree`; the
provenance of the run goes into it as one XML comment holding JSON, which
ParaView skips and :func:`read_pvd` reads back.

Layout of ``OUT.pvd``: the frame files go to the folder ``OUT/`` next to it,
``OUT/{part}_{k:04d}.vtu`` for frame ``k`` of each part (e.g. ``surface``
and ``t_vertices``), referenced relative to the ``.pvd``. Everything is
written at once, all or nothing (:func:`mcfbench.storage.atomic.atomic_path`
per file, renamed only when all are written); frame files that an earlier
collection at the same path listed and the new one does not are removed
afterwards (no other file is touched).
"""

import contextlib
import json
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mcfbench.storage.atomic import atomic_path, json_value

PROVENANCE_TAG = "mcfbench provenance "
"""Start of the XML comment of a ``.pvd`` that holds the provenance JSON."""


@dataclass
class Piece:
    """One part of one frame: a point set with cells and fields.

    Attributes
    ----------
    points : (n, 3) float array
    cells : (m, k) int array
        ``k = 3``: triangles; ``k = 1``: one vertex cell per point (a point
        cloud, e.g. the T-vertices of a DDFV state).
    point_data : dict of str -> (n,) or (n, 3) float arrays
    cell_data : dict of str -> (m,) or (m, 3) float arrays
    """

    points: np.ndarray
    cells: np.ndarray
    point_data: dict = field(default_factory=dict)
    cell_data: dict = field(default_factory=dict)

    def mesh(self):
        """The piece as a :class:`meshio.Mesh`, checking every shape."""
        import meshio  # on first use: only the exports pay for it

        points = np.asarray(self.points, dtype=np.float64)
        cells = np.asarray(self.cells)
        if points.ndim != 2 or points.shape[1] != 3:
            raise ValueError(f"points must be an (n, 3) array, got shape {points.shape}")
        if cells.ndim != 2 or cells.shape[1] not in CELL_TYPES or \
                not np.issubdtype(cells.dtype, np.integer):
            raise ValueError(f"cells must be an (m, 3) or (m, 1) int array, got {cells.dtype} "
                             f"{cells.shape}")
        if cells.size and (cells.min() < 0 or cells.max() >= len(points)):
            raise ValueError(f"cells refer to points outside 0..{len(points) - 1}")
        for kind, data, n in (("point", self.point_data, len(points)),
                              ("cell", self.cell_data, len(cells))):
            for name, values in data.items():
                if np.shape(values)[:1] != (n,):
                    raise ValueError(f"{kind} field {name!r} has shape {np.shape(values)}, "
                                     f"expected ({n}, ...)")
        return meshio.Mesh(
            points, [(CELL_TYPES[cells.shape[1]], cells.astype(np.int64))],
            point_data={k: np.asarray(v, dtype=np.float64) for k, v in self.point_data.items()},
            cell_data={k: [np.asarray(v, dtype=np.float64)] for k, v in self.cell_data.items()})


CELL_TYPES = {3: "triangle", 1: "vertex"}
"""meshio cell type of a cells array by its number of columns."""


def frame_file(pvd, part, k):
    """Path, relative to the folder of ``pvd``, of frame ``k`` of ``part``."""
    return f"{Path(pvd).stem}/{part}_{k:04d}.vtu"


def write_pvd(path, frames, times, provenance=None):
    """Write a ParaView collection: ``path`` (``.pvd``) and its frame files.

    Parameters
    ----------
    path : str or Path
        Ends in ``.pvd``.
    frames : sequence of dict of str -> Piece
        One dict per frame, part name -> piece (every frame has the same
        parts; a part is a ``part`` of the collection, in this order).
    times : (frames,) float array
        Time of each frame (the ``timestep`` ParaView shows).
    provenance : dict, optional
        JSON-able; stored in the ``.pvd`` (:func:`read_pvd` returns it).

    Returns
    -------
    list of Path
        Every file written, the ``.pvd`` last.

    Raises
    ------
    ValueError
        A path not ending in ``.pvd``, no frames, frames with different
        parts, a time count that differs from the frame count, non-finite
        times, or a piece with inconsistent shapes (named).
    """
    import meshio

    path = Path(path)
    if path.suffix != ".pvd":
        raise ValueError(f"{path}: a ParaView collection is a .pvd file; name it *.pvd")
    times = np.asarray(times, dtype=np.float64)
    if not len(frames):
        raise ValueError(f"{path}: no frames to write")
    if times.shape != (len(frames),) or not np.isfinite(times).all():
        raise ValueError(f"{path}: need one finite time per frame ({len(frames)}), got "
                         f"{times.tolist()}")
    parts = list(frames[0])
    meshes = {}
    for k, frame in enumerate(frames):
        if list(frame) != parts:
            raise ValueError(f"{path}: frame {k} has parts {list(frame)}, frame 0 {parts}")
        for part, piece in frame.items():
            try:
                meshes[frame_file(path, part, k)] = piece.mesh()
            except ValueError as err:
                raise ValueError(f"{path}: frame {k}, part {part!r}: {err}") from None
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    if provenance is not None:
        text = json.dumps(json_value(provenance), sort_keys=True, allow_nan=False)
        # "--" may not appear in an XML comment; inside JSON strings "\u002d" is "-"
        root.append(ET.Comment(" " + PROVENANCE_TAG + text.replace("--", "-\\u002d") + " "))
    collection = ET.SubElement(root, "Collection")
    for k, frame in enumerate(frames):
        for index, part in enumerate(parts):
            ET.SubElement(collection, "DataSet", timestep=repr(float(times[k])),
                          part=str(index), name=part, file=frame_file(path, part, k))
    ET.indent(root)
    xml = '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
    before = _listed_files(path)
    written = []
    with contextlib.ExitStack() as stack:
        for name, mesh in meshes.items():
            tmp = stack.enter_context(atomic_path(path.parent / name))
            meshio.write(tmp, mesh, file_format="vtu", binary=True, compression="zlib")
            written.append(path.parent / name)
        tmp = stack.enter_context(atomic_path(path))
        tmp.write_text(xml)
        written.append(path)
    for stale in before - set(written):
        stale.unlink(missing_ok=True)
    return written


def _listed_files(path):
    """The files an existing collection ``path`` lists (empty when there is none or it
    cannot be read): the frames an export over it may leave behind."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError):
        return set()
    return {path.parent / d.get("file") for d in root.iter("DataSet") if d.get("file")}


@dataclass
class Collection:
    """What :func:`read_pvd` found.

    Attributes
    ----------
    times : (frames,) float array
    parts : list of str
    files : dict of str -> list of Path
        Part -> its frame files (absolute), in time order.
    provenance : dict or None
    """

    times: np.ndarray
    parts: list
    files: dict
    provenance: dict = None

    def read(self, part, k):
        """Frame ``k`` of ``part`` as a :class:`meshio.Mesh`."""
        import meshio

        return meshio.read(self.files[part][k])


def read_pvd(path):
    """Read a collection written by :func:`write_pvd` (or any ``.pvd`` of datasets).

    Returns
    -------
    Collection

    Raises
    ------
    ValueError
        Not a ParaView collection, or a listed file is missing (named).
    """
    path = Path(path)
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    try:
        root = ET.parse(path, parser=parser).getroot()
    except ET.ParseError as err:
        raise ValueError(f"{path}: not an XML file ({err})") from None
    if root.tag != "VTKFile" or root.get("type") != "Collection":
        raise ValueError(f"{path}: not a ParaView collection (VTKFile type Collection)")
    provenance = None
    for node in root:
        if node.tag is ET.Comment and node.text.strip().startswith(PROVENANCE_TAG):
            provenance = json.loads(node.text.strip()[len(PROVENANCE_TAG):])
    times, parts, files = [], [], {}
    for dataset in root.iter("DataSet"):
        part = dataset.get("name") or dataset.get("part", "0")
        if part not in files:
            parts.append(part)
            files[part] = []
        file = path.parent / dataset.get("file")
        if not file.is_file():
            raise ValueError(f"{path}: lists {dataset.get('file')}, which is missing")
        files[part].append(file)
        if part == parts[0]:
            times.append(float(dataset.get("timestep", "nan")))
    return Collection(times=np.array(times), parts=parts, files=files, provenance=provenance)
