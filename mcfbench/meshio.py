"""Reading triangle meshes (OBJ, OFF, PLY, STL, ... through libigl)."""

from pathlib import Path

import igl
import numpy as np


def read_mesh(path):
    """Read a triangle mesh file.

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    vertices : (n, 3) float array
    faces : (m, 3) int array
        In the order of the file.

    Raises
    ------
    FileNotFoundError, ValueError
        Missing file, or a file with no triangles (unreadable format or
        polygons that are not triangles).
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"mesh file not found: {path}")
    V, F = igl.read_triangle_mesh(str(path))
    V, F = np.asarray(V, dtype=float), np.asarray(F, dtype=np.int64)
    if F.ndim != 2 or F.shape[1] != 3 or len(F) == 0 or V.ndim != 2 or V.shape[1] != 3:
        raise ValueError(f"{path}: no triangle mesh could be read "
                         f"(got vertices {V.shape}, faces {F.shape})")
    return V, F
