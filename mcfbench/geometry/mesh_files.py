"""Reading triangle meshes from files (OBJ, OFF, PLY, STL through libigl).

:func:`read_mesh` reads a file, repairs what can be repaired without
changing the surface, validates the result with
:func:`mcfbench.geometry.mesh.validate_mesh` and says what it did in an
:class:`IntakeReport`.

Errors
------
Always ``FileNotFoundError`` (no such path) or ``ValueError`` naming the
file: a directory, an empty file, an extension other than ``.obj .off .ply
.stl``, content libigl cannot read (its message is quoted), NaN/inf
coordinates (the vertex is named, with its line for OBJ and OFF), a face
with fewer than 3 corners, no faces, or an invalid surface
(:class:`mcfbench.geometry.mesh.MeshError`, vertices and triangles named in the
file's numbering). libigl reads in a forked child process where the
platform has ``fork``, so a crash of the reader (libigl aborts on a PLY
with faces of different sizes) becomes a ``ValueError`` too.

Intake, in this order, each counted in the report
------------------------------------------------
1. Polygons: faces with more than 3 corners are split into triangles by a
   fan from their first corner (libigl does so for OBJ and OFF; we do the
   same for PLY files whose faces all have ``k > 3`` corners). The
   triangles of a polygon are consecutive. Fine for convex, planar
   polygons; triangulate others before.
2. Unreferenced vertices (used by no face) are dropped. NaN/inf
   coordinates anywhere in the file are refused before that.
3. Coincident vertices (exactly equal coordinates, ``-0.0 == 0.0``) are
   merged into the first of them in the file. This turns an STL triangle
   soup (libigl reads three vertices per triangle) into a connected
   surface and closes duplicated seams. Points that are only close are
   not merged.

Numbering
---------
Vertices keep the order of the file. ``report.kept[i]`` is the file's
(0-based) index of mesh vertex ``i``; ``report.new_index[j]`` the mesh
vertex of file vertex ``j`` (``-1`` if dropped). To write results in the
file's numbering: ``report.to_file_order(X)`` for per-vertex values and
``report.kept[F]`` for faces. ``report.face_of[t]`` is the file's face of
triangle ``t``.
"""

import faulthandler
import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path

import igl
import numpy as np

from mcfbench.geometry.mesh import MeshError, count_phrase, first_ids, validate_mesh

SUPPORTED = (".obj", ".off", ".ply", ".stl")


@dataclass(frozen=True)
class IntakeReport:
    """What :func:`read_mesh` read and repaired (see the module docstring).

    Attributes
    ----------
    path : str
    file_vertices, file_faces : int
        As in the file (a polygon counts as one face).
    polygons : int
        Faces with more than 3 corners, split into triangles.
    dropped : int
        Unreferenced vertices dropped.
    merged : int
        Vertices merged into an earlier coincident one.
    kept : (n,) int array
        File vertex of each mesh vertex.
    new_index : (file_vertices,) int array
        Mesh vertex of each file vertex, ``-1`` if dropped.
    face_of : (m,) int array
        File face of each triangle.
    """

    path: str
    file_vertices: int
    file_faces: int
    polygons: int
    dropped: int
    merged: int
    kept: np.ndarray
    new_index: np.ndarray
    face_of: np.ndarray

    @property
    def triangles(self):
        return len(self.face_of)

    def notes(self):
        """One line per repair made, e.g. ``"merged 34 coincident vertices"``."""
        notes = []
        if self.polygons:
            notes.append(f"split {count_phrase(self.polygons, 'polygon')} into "
                         f"{self.triangles - (self.file_faces - self.polygons)} "
                         "triangles (fan from the first corner)")
        if self.dropped:
            notes.append(f"dropped {count_phrase(self.dropped, 'unreferenced vertex', 'unreferenced vertices')}")
        if self.merged:
            notes.append(f"merged {count_phrase(self.merged, 'coincident vertex', 'coincident vertices')}")
        return notes

    def to_file_order(self, values, fill=np.nan):
        """Per-vertex ``values`` (n, ...) in the file's numbering.

        Returns an array of ``file_vertices`` rows: file vertex ``j`` gets
        the value of its mesh vertex (merged copies share it), dropped
        vertices get ``fill``.
        """
        values = np.asarray(values)
        out = np.full((self.file_vertices,) + values.shape[1:], fill,
                      dtype=np.result_type(values, np.min_scalar_type(fill)))
        used = self.new_index >= 0
        out[used] = values[self.new_index[used]]
        return out


def read_mesh(path):
    """Read a triangle mesh file, repair it (see module docstring) and validate it.

    Parameters
    ----------
    path : str or Path
        A ``.obj``, ``.off``, ``.ply`` or ``.stl`` file.

    Returns
    -------
    V : (n, 3) float64 array
    F : (m, 3) int64 array
        A valid surface (:func:`mcfbench.geometry.mesh.validate_mesh`).
    report : IntakeReport

    Raises
    ------
    FileNotFoundError
        The path does not exist.
    ValueError
        Anything else, with the file's name (see module docstring).
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"mesh file not found: {path}")
    if path.is_dir():
        raise ValueError(f"{path} is a directory, not a mesh file")
    if not path.is_file():
        raise ValueError(f"{path} is not a regular file")
    ext = path.suffix.lower()
    if ext not in SUPPORTED:
        raise ValueError(f"{path}: unsupported mesh format {ext or '(no extension)'!r}; "
                         f"supported: {' '.join(SUPPORTED)}")
    if path.stat().st_size == 0:
        raise ValueError(f"{path}: the file is empty")

    try:
        V, F = _libigl_read(path, ext)
    except ValueError:
        _refuse_vertex_lines(path, ext)     # libigl's OBJ reader fails on "v nan 0 0"
        raise
    if len(V) == 0 and len(F) == 0:
        raise ValueError(f"{path}: no vertices and no faces could be read "
                         f"(not a valid {ext[1:].upper()} file?)")
    nonfinite = np.flatnonzero(~np.isfinite(V).all(axis=1))
    if len(nonfinite):
        _refuse_vertex_lines(path, ext)
        raise ValueError(f"{path}: NaN or inf coordinates at vertex(es) {first_ids(nonfinite)} "
                         "(0-based, in the order of the file)")
    scan = _scan(path, ext)

    # faces: sizes as in the file, triangles as libigl gives them
    file_faces, polygons, face_of = len(F), 0, np.arange(len(F))
    if scan is not None:
        short = np.flatnonzero(scan.sizes < 3)
        if len(short):
            j = short[0]
            raise ValueError(f"{path}: face(s) {first_ids(short)} have fewer than 3 corners, e.g. "
                             f"face {j} (line {scan.face_lines[j]}) has {scan.sizes[j]}")
        expected = np.maximum(scan.sizes - 2, 0)
        if expected.sum() == len(F):
            file_faces, polygons = len(scan.sizes), int((scan.sizes > 3).sum())
            face_of = np.repeat(np.arange(len(scan.sizes)), expected)
    if F.ndim == 2 and len(F) and F.shape[1] != 3:
        k = F.shape[1]
        if k < 3:
            raise ValueError(f"{path}: faces have {k} corner(s); a face needs at least 3")
        file_faces, polygons = len(F), len(F)
        face_of = np.repeat(np.arange(len(F)), k - 2)
        F = np.stack([np.repeat(F[:, :1], k - 2, axis=1), F[:, 1:-1], F[:, 2:]],
                     axis=2).reshape(-1, 3)
    if len(F) == 0:
        raise ValueError(f"{path}: the file has {len(V)} vertices but no faces "
                         "(a point cloud is not a surface)")
    out = np.flatnonzero(((F < 0) | (F >= len(V))).any(axis=1))
    if len(out):
        raise ValueError(f"{path}: face(s) {first_ids(face_of[out])} refer to vertices that do "
                         f"not exist (the file has {len(V)} vertices)")

    # drop unreferenced vertices, then merge coincident ones (first one wins)
    used = np.flatnonzero(np.bincount(F.ravel(), minlength=len(V)) > 0)
    _, first, inverse = np.unique(V[used] + 0.0, axis=0, return_index=True,
                                  return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(first)             # unique points in file order
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    kept = used[first[order]]
    new_index = np.full(len(V), -1, dtype=np.int64)
    new_index[used] = rank[inverse]
    report = IntakeReport(
        path=str(path), file_vertices=len(V), file_faces=file_faces, polygons=polygons,
        dropped=len(V) - len(used), merged=len(used) - len(kept), kept=kept,
        new_index=new_index, face_of=face_of)

    try:
        V, F = validate_mesh(V[kept], new_index[F], vertex_ids=kept, face_ids=face_of)
    except MeshError as err:
        hint = ""
        if report.merged and err.kind in ("repeated vertex", "duplicate triangle",
                                          "non-manifold edge", "non-manifold vertex"):
            hint = (f" (after merging {count_phrase(report.merged, 'coincident vertex', 'coincident vertices')}; "
                    "vertices are named by their first copy in the file)")
        raise MeshError(err.kind, f"{path}: {err}{hint} (numbers are 0-based, in the "
                        "order of the file)") from None
    return V, F, report


# --- libigl, isolated ---------------------------------------------------

def _libigl_read(path, ext):
    """``igl.read_triangle_mesh`` in a forked child; ValueError if it fails.

    The child's stdout/stderr (where libigl writes its reasons) are kept
    for the message; a crash of the child is reported, not inherited.
    """
    if not hasattr(os, "fork"):
        return _libigl_read_here(path, ext)
    with tempfile.TemporaryDirectory(prefix="mcfbench-read-") as tmp:
        log, out_v, out_f = (os.path.join(tmp, name) for name in ("log", "V.npy", "F.npy"))
        pid = os.fork()
        if pid == 0:  # child: never returns
            code = 1
            try:
                faulthandler.disable()  # a crash is reported by the parent
                fd = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
                os.dup2(fd, 1)
                os.dup2(fd, 2)
                V, F = igl.read_triangle_mesh(str(path))[:2]
                np.save(out_v, np.asarray(V, dtype=np.float64))
                np.save(out_f, np.asarray(F, dtype=np.int64))
                code = 0
            except BaseException as err:  # noqa: BLE001 - reported by the parent
                try:
                    os.write(2, f"\n{err}".encode(errors="replace"))
                except BaseException:  # noqa: BLE001
                    pass
            finally:
                os._exit(code)
        _, status = os.waitpid(pid, 0)
        code = os.waitstatus_to_exitcode(status)
        text = _log_text(log)
        if code == 0:
            return np.load(out_v), np.load(out_f)
    crashed = f" (the reader crashed with signal {-code})" if code < 0 else ""
    raise ValueError(f"{path}: libigl could not read this {ext[1:].upper()} file{crashed}: "
                     f"{text or 'no reason given'}")


def _libigl_read_here(path, ext):
    try:
        V, F = igl.read_triangle_mesh(str(path))[:2]
    except RuntimeError as err:
        raise ValueError(f"{path}: libigl could not read this {ext[1:].upper()} file: "
                         f"{err}") from None
    return np.asarray(V, dtype=np.float64), np.asarray(F, dtype=np.int64)


def _log_text(log, limit=300):
    try:
        with open(log, "rb") as fh:
            raw = fh.read(4 * limit)
    except OSError:
        return ""
    text = " ".join(raw.decode(errors="replace").split())
    return text if len(text) <= limit else text[:limit] + "..."


# --- a light scan of text formats, for line numbers and face sizes -------

@dataclass
class _Scan:
    sizes: np.ndarray           # corners of each face, in file order
    face_lines: list            # line number of each face
    bad_vertices: list          # (index, line number, text) of unusable vertex lines


def _scan(path, ext, vertices=False):
    """Scan an OBJ or OFF file; None for other formats or if it does not parse.

    Face sizes always; with ``vertices``, also the vertex lines whose
    coordinates are not three finite numbers (slower).
    """
    try:
        if ext == ".obj":
            return _scan_obj(path, vertices)
        if ext == ".off":
            return _scan_off(path, vertices)
    except (OSError, ValueError, IndexError):
        return None
    return None


def _bad_coordinates(tokens):
    try:
        xyz = [float(t) for t in tokens[:3]]
    except ValueError:
        return True
    return len(xyz) < 3 or not all(math.isfinite(x) for x in xyz)


def _scan_obj(path, vertices):
    sizes, face_lines, bad = [], [], []
    n_v = 0
    with open(path, "rb") as fh:
        for number, line in enumerate(fh, 1):
            head = line.lstrip()[:2]
            if head == b"f " or head == b"f\t":
                sizes.append(len(line.split(b"#", 1)[0].split()) - 1)
                face_lines.append(number)
            elif vertices and (head == b"v " or head == b"v\t"):
                if _bad_coordinates(line.split(b"#", 1)[0].split()[1:]):
                    bad.append((n_v, number, line.decode(errors="replace").strip()))
                n_v += 1
    return _Scan(np.array(sizes, dtype=np.int64), face_lines, bad)


def _scan_off(path, vertices):
    with open(path, "rb") as fh:
        lines = [(number, line.split(b"#", 1)[0].split())
                 for number, line in enumerate(fh, 1)]
    lines = [(number, tokens) for number, tokens in lines if tokens]
    (_, header), rest = lines[0], lines[1:]
    if not header[0].endswith(b"OFF") or b"BINARY" in header[0].upper() or (
            len(header) > 1 and header[1].upper() == b"BINARY"):
        raise ValueError("not a text OFF file")
    counts = header[1:] if len(header) > 1 else rest.pop(0)[1]
    n_v, n_f = int(counts[0]), int(counts[1])
    bad = [(i, number, b" ".join(tokens).decode(errors="replace"))
           for i, (number, tokens) in enumerate(rest[:n_v])
           if vertices and _bad_coordinates(tokens)]
    faces = rest[n_v:n_v + n_f]
    sizes = np.array([int(tokens[0]) for _, tokens in faces], dtype=np.int64)
    return _Scan(sizes, [number for number, _ in faces], bad)


def _refuse_vertex_lines(path, ext):
    """Name the first vertex line with NaN, inf or unreadable coordinates, if any."""
    scan = _scan(path, ext, vertices=True)
    if scan is None or not scan.bad_vertices:
        return
    bad = scan.bad_vertices
    i, number, text = bad[0]
    more = f" ({len(bad) - 1} more such vertices)" if len(bad) > 1 else ""
    if len(text) > 80:
        text = text[:80] + "..."
    raise ValueError(f"{path}: NaN, inf or unreadable coordinates at vertex {i} "
                     f"(0-based; line {number}: {text!r}){more}") from None
