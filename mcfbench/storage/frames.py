"""The one frame-file layout: the kept frames of one run in one ``.npz``.

Keys (every study's frames file, the ``run`` command's ``--out``):

* ``vertices`` (frames, n, 3): the surface mesh's vertices, whatever the scheme
  (DDFV's F-vertices);
* ``extra_points`` (frames, k, 3), only for a scheme whose state has points
  besides the mesh vertices (:attr:`mcfbench.running.schemes.Scheme.extra_points`:
  DDFV's T-vertices, one per triangle; left out when the scheme refused the
  surface: the initial surface);
* ``faces`` (m, 3), ``steps`` (frames,) the time levels kept, ``t`` (frames,)
  their times;
* ``format_version`` (a 0-d int array): :data:`FORMAT_VERSION`, written by
  :func:`save_frames`; :func:`load_frames` refuses a newer one and drops the key;
* anything else the writer adds (the ``run`` command: status, provenance).

The state of a frame is ``vertices`` then ``extra_points`` (the order of the
scheme's ``X``).

**Versions.** ``format_version`` (a 0-d int array; :data:`FORMAT_VERSION`) says
which layout a file has (0: before the key, 1: the layout above). Version 2
adds the frames of a run whose mesh changed (a remeshed run,
:mod:`mcfbench.running.remeshing`): each frame keeps its own faces, so the frames
cannot be stacked. Such a file has no ``vertices`` and ``extra_points`` but
``frame_vertices`` (sum n_k, 3), ``frame_extra_points`` (sum k_k, 3),
``frame_faces`` (sum m_k, 3), each frame's rows one after the other, and
``frame_sizes`` (frames, 3), the ``n_k, k_k, m_k`` of each; ``faces`` is frame 0's.
A run whose mesh stayed has the stacked layout in both versions. Read a frame's
mesh with :func:`frame_mesh` (both layouts), its points with :func:`surface_points`
(lists of arrays for the changing layout). A run whose mesh was refused before any frame (the gallery) has
empty ``faces``, ``steps`` and ``t`` and no vertices. :func:`surface_points`
reads the points of any run's frames alike. :func:`save_frames` writes
(atomically, :func:`mcfbench.storage.atomic.save_npz`), :func:`load_frames`
reads; both check the layout. Files written before this layout (keys ``V``, or
``F`` and ``T``) are read as if written with it (:data:`LEGACY_KEYS`), and so are
files of this layout written before ``format_version`` existed. Every change of the
keys is listed in ``docs/formats.md``.
"""

import zipfile
import zlib
from pathlib import Path

import numpy as np

from mcfbench.storage.atomic import save_npz

FORMAT_VERSION = 2
"""The version of the layout :func:`save_frames` writes (``docs/formats.md``); a file
without the key is read as the layout before it (version 0, :data:`LEGACY_KEYS`);
2 adds the frames with their own faces (module docstring)."""

REQUIRED = ("faces", "steps", "t")
"""Keys of every frames file."""

CHANGING = ("frame_vertices", "frame_faces", "frame_sizes")
"""Keys of the frames of a run whose mesh changed (version 2)."""

LEGACY_KEYS = {"V": "vertices", "F": "vertices", "T": "extra_points"}
"""Keys of the frames files written before the one layout (a vertex scheme's ``V``,
DDFV's F- and T-vertices ``F``, ``T``) -> theirs now: :func:`load_frames` renames them."""


def check_frames(arrays, path):
    """Raise ValueError naming ``path`` unless ``arrays`` has the layout.

    Raises
    ------
    ValueError
        A key of :data:`REQUIRED` missing, or frames (``t`` not empty)
        without ``vertices``.
    """
    missing = [key for key in REQUIRED if key not in arrays]
    changing = all(key in arrays for key in CHANGING)
    if missing or (len(arrays["t"]) and "vertices" not in arrays and not changing):
        raise ValueError(f"{path}: not a run's frames file: it has {sorted(arrays)}, expected "
                         f"faces, steps, t and vertices (and extra_points), or frame_vertices, "
                         f"frame_faces and frame_sizes")
    if changing:
        sizes = np.asarray(arrays["frame_sizes"])
        if sizes.shape != (len(arrays["t"]), 3) or \
                sizes[:, 0].sum() != len(arrays["frame_vertices"]) or \
                sizes[:, 2].sum() != len(arrays["frame_faces"]):
            raise ValueError(f"{path}: frame_sizes {sizes.shape} does not match the frames' "
                             f"{len(arrays['t'])} times and their rows")


def changing_frames(vertices, extra, faces):
    """The version-2 arrays of frames each with its own mesh (module docstring).

    Parameters
    ----------
    vertices : list of (n_k, 3) float arrays
    extra : list of (k_k, 3) float arrays, or None
    faces : list of (m_k, 3) int arrays

    Returns
    -------
    dict
        ``frame_vertices``, ``frame_extra_points`` (with ``extra``), ``frame_faces``,
        ``frame_sizes`` and ``faces`` (frame 0's).
    """
    extra_sizes = [len(e) for e in extra] if extra is not None else [0] * len(vertices)
    packed = {"frame_vertices": np.concatenate(vertices),
              "frame_faces": np.concatenate(faces),
              "frame_sizes": np.array([[len(v), k, len(f)] for v, k, f in
                                       zip(vertices, extra_sizes, faces)], dtype=np.int64),
              "faces": np.asarray(faces[0])}
    if extra is not None:
        packed["frame_extra_points"] = np.concatenate(extra)
    return packed


def _split(arrays, key, column):
    """The rows of ``key`` cut by ``frame_sizes[:, column]``: a list of arrays."""
    bounds = np.cumsum(arrays["frame_sizes"][:, column])[:-1]
    return np.split(np.asarray(arrays[key]), bounds)


def frame_mesh(frames, k):
    """``(vertices, faces)`` of frame ``k`` of a run's frames, either layout."""
    if "frame_sizes" in frames:
        return _split(frames, "frame_vertices", 0)[k], _split(frames, "frame_faces", 2)[k]
    return frames["vertices"][k], frames["faces"]


def mesh_segments(frames):
    """The frames in runs of one mesh: ``[(faces, vertices, extra)]``, ``vertices``
    (frames_s, n_s, 3) stacked, ``extra`` (frames_s, k_s, 3) or None, in frame order;
    one segment for a run whose mesh stayed, one per remesh more for a remeshed run
    (a reader that compares frames, e.g. their displacements, compares within one)."""
    vertices, extra = surface_points(frames)
    if "frame_sizes" not in frames:
        return [(np.asarray(frames["faces"]), vertices, extra)] if vertices is not None \
            else []
    faces = _split(frames, "frame_faces", 2)
    segments, start = [], 0
    for k in range(1, len(faces) + 1):
        if k == len(faces) or not np.array_equal(faces[k], faces[start]):
            segments.append((faces[start], np.stack(vertices[start:k]),
                             None if extra is None else np.stack(extra[start:k])))
            start = k
    return segments


def surface_points(frames):
    """``(vertices, extra)`` of a run's frames (a frames file's arrays, or the
    trajectory's): the surface mesh's vertices (frames, n, 3), a DDFV run's
    F-vertices, and the extra points (frames, k, 3), DDFV's T-vertices, or None.
    ``vertices`` is None when the run kept no frame. What reads a frame takes its
    points from here, whatever the scheme. For frames whose mesh changed (version 2)
    both are lists of the frames' (n_k, 3) and (k_k, 3) arrays (indexed as the
    stacked ones; each frame's faces by :func:`frame_mesh`)."""
    if "frame_sizes" in frames:
        extra = _split(frames, "frame_extra_points", 1) if "frame_extra_points" in frames \
            else None
        return _split(frames, "frame_vertices", 0), extra
    return frames.get("vertices"), frames.get("extra_points")


def save_frames(path, frames):
    """Write one run's frames (:func:`check_frames`) atomically to ``path``."""
    check_frames(frames, path)
    save_npz(path, **{**frames, "format_version": np.array(FORMAT_VERSION)})


def load_frames(path):
    """The arrays of one run's frames file as a dict.

    Raises
    ------
    FileNotFoundError
        No file ``path``.
    ValueError
        Not an ``.npz`` archive (a zip of NumPy arrays: a mesh, a text file, a
        single ``.npy``), unreadable, holding Python objects, or not the layout
        (:func:`check_frames`); the message names the file.
    """
    path = Path(path)
    if not path.is_file():
        if not path.exists():
            raise FileNotFoundError(f"{path}: the file does not exist")
        raise ValueError(f"{path}: a folder, not a run's .npz")
    if not zipfile.is_zipfile(path):      # np.load would try it as a pickle
        raise ValueError(f"{path}: not a run's .npz (not a zip of NumPy arrays)")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {LEGACY_KEYS.get(key, key): data[key] for key in data.files}
    except ValueError as err:
        if "allow_pickle" in str(err):    # NumPy's advice to load it unsafely
            raise ValueError(f"{path}: not a run's .npz (it holds Python objects, "
                             f"which a run's file never has)") from None
        raise ValueError(f"{path}: not a run's .npz ({err})") from None
    except (OSError, EOFError, zipfile.BadZipFile, zlib.error) as err:
        raise ValueError(f"{path}: not a readable .npz ({err})") from None
    check_version(arrays.pop("format_version", np.array(0)).tolist(), FORMAT_VERSION, path,
                  "frames file")
    check_frames(arrays, path)
    return arrays


def check_version(version, newest, path, what):
    """Raise ValueError naming ``path`` when ``version`` (a file's ``format_version``)
    is not an integer from 0 (before the key existed) to ``newest``, the version
    this code writes: a newer file's keys may mean what this reader does not know."""
    try:
        number = int(version)
    except (TypeError, ValueError):
        number = None
    if number is None or number != version or number < 0:
        raise ValueError(f"{path}: format_version {version!r} is not a version number "
                         f"(0 to {newest}) of a {what}")
    if number > newest:
        raise ValueError(f"{path}: a {what} of format_version {number}, written by a newer "
                         f"mcfbench; this one reads versions up to {newest} (update mcfbench, "
                         f"or see docs/formats.md for what changed)")
