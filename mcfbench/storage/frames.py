"""The one frame-file layout: the kept frames of one run in one ``.npz``.

Keys (every study's frames file, the ``run`` command's ``--out``):

* ``V`` (frames, n, 3): the vertices of a vertex scheme, or ``F`` (frames,
  n_f, 3) and ``T`` (frames, n_t, 3): the F- and T-vertices of a DDFV scheme
  (``F`` alone when the scheme refused the surface: the initial surface);
* ``faces`` (m, 3), ``steps`` (frames,) the time levels kept, ``t`` (frames,)
  their times;
* anything else the writer adds (the ``run`` command: status, provenance).

A run whose mesh was refused before any frame (the gallery) has empty
``faces``, ``steps`` and ``t`` and no vertices. :func:`surface_points` reads
the points of any run's frames alike. :func:`save_frames` writes
(atomically, :func:`mcfbench.storage.atomic.save_npz`), :func:`load_frames`
reads; both check the layout.
"""

import zipfile
import zlib
from pathlib import Path

import numpy as np

from mcfbench.storage.atomic import save_npz

REQUIRED = ("faces", "steps", "t")
"""Keys of every frames file."""


def check_frames(arrays, path):
    """Raise ValueError naming ``path`` unless ``arrays`` has the layout.

    Raises
    ------
    ValueError
        A key of :data:`REQUIRED` missing, or frames (``t`` not empty)
        without ``V`` or ``F``.
    """
    missing = [key for key in REQUIRED if key not in arrays]
    if missing or (len(arrays["t"]) and not ("V" in arrays or "F" in arrays)):
        raise ValueError(f"{path}: not a run's frames file: it has {sorted(arrays)}, expected "
                         f"faces, steps, t and V (or F and T)")


def surface_points(frames):
    """``(vertices, extra)`` of a run's frames (a frames file's arrays, or the
    trajectory's): the surface mesh's vertices (frames, n, 3), a DDFV run's
    F-vertices, and the extra points (frames, k, 3), DDFV's T-vertices, or None.
    ``vertices`` is None when the run kept no frame. What reads a frame takes its
    points from here, whatever the scheme."""
    return frames.get("F", frames.get("V")), frames.get("T")


def save_frames(path, frames):
    """Write one run's frames (:func:`check_frames`) atomically to ``path``."""
    check_frames(frames, path)
    save_npz(path, **frames)


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
            arrays = {key: data[key] for key in data.files}
    except ValueError as err:
        if "allow_pickle" in str(err):    # NumPy's advice to load it unsafely
            raise ValueError(f"{path}: not a run's .npz (it holds Python objects, "
                             f"which a run's file never has)") from None
        raise ValueError(f"{path}: not a run's .npz ({err})") from None
    except (OSError, EOFError, zipfile.BadZipFile, zlib.error) as err:
        raise ValueError(f"{path}: not a readable .npz ({err})") from None
    check_frames(arrays, path)
    return arrays
