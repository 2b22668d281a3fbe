"""Atomic output: every file the suite writes goes to a temporary file in the
same directory and is renamed over the target, so that a kill at any moment
leaves either the old file or the new one, never a partial one.
"""

import contextlib
import json
import math
import os
import tempfile
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path, mode=0o644):
    """Yield a temporary path next to ``path``; rename it to ``path`` on success.

    The temporary file is removed when the body raises. The directory is
    created when missing.

    Parameters
    ----------
    path : str or Path
    mode : int
        Permissions of the final file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        yield Path(tmp)
        with open(tmp, "rb+") as handle:
            os.fsync(handle.fileno())
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text(path, text):
    """Write ``text`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text)


def json_value(value):
    """``value`` with non-finite floats as ``None`` (standard JSON), recursively."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {str(k): json_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_value(v) for v in value]
    if hasattr(value, "item") and getattr(value, "ndim", 1) == 0:  # numpy scalars
        return json_value(value.item())
    return value


def json_text(data):
    """``data`` as indented standard JSON text (NaN as ``null``, :func:`json_value`)."""
    return json.dumps(json_value(data), indent=2, allow_nan=False) + "\n"


def write_json(path, data):
    """Write ``data`` as indented standard JSON (NaN as ``null``) atomically."""
    write_text(path, json_text(data))


def save_npz(path, **arrays):
    """``numpy.savez_compressed`` to exactly ``path`` (no ``.npz`` appended), atomically."""
    import numpy as np

    with atomic_path(path) as tmp:
        with open(tmp, "wb") as handle:
            np.savez_compressed(handle, **arrays)


def save_figure(fig, *paths, dpi=150):
    """Save a matplotlib figure to each path (``None`` skipped) at once, as
    :func:`write_files`, and close it."""
    write_files({path: fig for path in paths if path is not None}, dpi=dpi)


def _figure_metadata(suffix):
    """Metadata without creation dates, so that the same figure gives the same bytes."""
    if suffix == ".pdf":
        return {"CreationDate": None}
    if suffix == ".svg":
        return {"Date": None}
    return {}


def check_writable(path):
    """Refuse, before any work, an output ``path`` that cannot be written.

    Raises
    ------
    ValueError
        The parent is a file, or the directory is not writable, or ``path``
        is a directory; the message names the path.
    """
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"output {path} is a directory")
    parent = path.parent
    for ancestor in (parent, *parent.parents):
        if ancestor.exists():
            if not ancestor.is_dir():
                raise ValueError(f"cannot write {path}: {ancestor} is a file, not a directory")
            if not os.access(ancestor, os.W_OK | os.X_OK):
                raise ValueError(f"cannot write {path}: directory {ancestor} is not writable")
            break


def write_files(files, dpi=200):
    """Write every output of a job, all or nothing.

    ``files`` maps a path to its content: text, bytes, a matplotlib figure
    (saved in the format of the suffix at ``dpi``, without dates)
    or ``(figure, savefig keyword arguments)``. Every content goes to a
    temporary file next to its target first; only when all are written are
    they renamed over the targets, so a failure leaves every previous output
    in place. The figures are closed.
    """
    figures = []
    try:
        with contextlib.ExitStack() as stack:
            for path, content in files.items():
                tmp = stack.enter_context(atomic_path(path))
                if isinstance(content, str):
                    tmp.write_text(content)
                elif isinstance(content, bytes):
                    tmp.write_bytes(content)
                else:
                    fig, options = content if isinstance(content, tuple) else (content, {})
                    figures.append(fig)
                    suffix = Path(path).suffix
                    fig.savefig(tmp, **{"dpi": dpi, "format": suffix.lstrip("."),
                                        "metadata": _figure_metadata(suffix), **options})
    finally:
        if figures:
            import matplotlib.pyplot as plt

            for fig in set(figures):
                plt.close(fig)
