"""A run's frames as an animated GIF (``mcfbench run --movie NAME.gif``, ``mcfbench export``,
the gallery's ``movies/``).

Each frame is drawn by :func:`mcfbench.presentation.render.draw_mesh` (DDFV:
the diamond mesh, F- and T-vertices; the other schemes: the triangles) with
one camera and one scale for the whole run (the box of every frame's
projection), so a shrinking surface looks smaller and a fixed boundary
stays in place. Each frame is labelled with its time and step, and with the
run's status at that frame: ``ok`` until the step at which the run broke
down or a defect was first seen, then that status (in red) and, on the last
frame, its message. matplotlib's :class:`~matplotlib.animation.FuncAnimation`
draws the frames and :class:`~matplotlib.animation.PillowWriter` encodes
them; the file is written atomically.
"""

import tempfile
import textwrap
from pathlib import Path

import numpy as np
from matplotlib.animation import FuncAnimation, PillowWriter

from mcfbench.presentation.render import draw_mesh, project
from mcfbench.storage.atomic import write_files
from mcfbench.storage.frames import frame_mesh, surface_points

OK_COLOR, DEFECT_COLOR = "#1a7f37", "#c0261c"


def frame_status(steps, status="ok", failed_step=-1):
    """The status shown on each frame: ``"ok"`` before ``failed_step``, ``status`` from it on.

    Parameters
    ----------
    steps : (frames,) int array
        Time level of each frame.
    status : str
    failed_step : int
        Time level of the breakdown or first defect, ``-1`` when none.

    Returns
    -------
    list of str
    """
    steps = np.asarray(steps)
    if status == "ok" or failed_step < 0:
        return [status] * len(steps)
    return [status if step >= failed_step else "ok" for step in steps]


def view_box(points, view, margin=0.05):
    """``(centre, half)`` of the square that holds the projection of every frame.

    Parameters
    ----------
    points : sequence of (n, 3) float arrays
        The points of each frame (non-finite ones are left out).
    view : (elev, azim) in degrees
    margin : float
        Empty border, relative to the extent.

    Returns
    -------
    centre : (2,) float array
    half : float
        Half the side of the square.
    """
    xy = [project(p[np.isfinite(p).all(axis=1)], view)[0] for p in points]
    xy = np.concatenate([x for x in xy if len(x)] or [np.zeros((1, 2))])
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    half = 0.5 * (1 + 2 * margin) * max(float((hi - lo).max()), 1e-12)
    return 0.5 * (lo + hi), half


def write_movie(arrays, out, *, title="", view=(20.0, -60.0), fps=4, size=4.0, dpi=100):
    """Animate the frames of a run into the GIF ``out``.

    Parameters
    ----------
    arrays : dict
        ``faces`` (m, 3), ``t`` (frames,), ``vertices`` (frames, n, 3) and, for
        DDFV, ``extra_points`` (frames, m, 3), the T-vertices; optional ``steps``
        (frames,), ``status``, ``message``, ``failed_step`` (a run ``.npz``).
    out : str or Path
        Ends in ``.gif``.
    title : str
        Above every frame (e.g. the scheme and the mesh).
    view : (elev, azim) in degrees
    fps : float
        Frames per second.
    size : float
        Width and height in inches (``size * dpi`` pixels).

    Returns
    -------
    Path
        ``out``.

    Raises
    ------
    ValueError
        ``out`` not a ``.gif``, or no frames.
    """
    import matplotlib.pyplot as plt

    out = Path(out)
    if out.suffix.lower() != ".gif":
        raise ValueError(f"{out}: the animation is a GIF; name it *.gif")
    # a DDFV run the scheme refused (status unsupported) kept its surface, no T-vertices
    V, T = surface_points(arrays)
    if "frame_sizes" not in arrays:          # one mesh (a remeshed run's: lists, per frame)
        V = np.asarray(V if V is not None else [], dtype=float)
        T = None if T is None else np.asarray(T, dtype=float)
    faces, t = np.asarray(arrays["faces"]), np.asarray(arrays["t"], dtype=float)
    if len(t) == 0 or len(V) != len(t):
        raise ValueError(f"{out}: no frames to animate ({len(V)} frames, {len(t)} times)")
    steps = np.asarray(arrays.get("steps", np.arange(len(t))))
    status = str(arrays.get("status", "ok"))
    message = str(arrays.get("message", ""))
    statuses = frame_status(steps, status, int(arrays.get("failed_step", -1)))
    centre, half = view_box([np.concatenate([V[k], T[k]]) if T is not None else V[k]
                             for k in range(len(t))], view)
    fig, ax = plt.subplots(figsize=(size, size))
    fig.subplots_adjust(left=0.02, right=0.98, top=0.9, bottom=0.12)

    def draw(k):
        ax.clear()
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_aspect("equal")
        ax.set_axis_off()
        finite = np.isfinite(V[k]).all() and (T is None or np.isfinite(T[k]).all())
        if finite:
            draw_mesh(ax, V[k], None if T is None else T[k], frame_mesh(arrays, k)[1], view=view,
                      points_per_unit=72.0 * size / (2 * half))
        else:
            ax.text(0.5, 0.5, "non-finite coordinates", transform=ax.transAxes,
                    ha="center", va="center", color=DEFECT_COLOR)
        if title:
            ax.set_title(title, fontsize=9)
        ax.text(0.02, -0.02, f"t = {t[k]:.5g}  (step {int(steps[k])})", transform=ax.transAxes,
                ha="left", va="top", fontsize=9, family="monospace")
        ok = statuses[k] == "ok"
        ax.text(0.98, -0.02, statuses[k], transform=ax.transAxes, ha="right", va="top",
                fontsize=9, weight="bold", color=OK_COLOR if ok else DEFECT_COLOR)
        if not ok and k == len(t) - 1 and message:
            ax.text(0.5, -0.08, textwrap.shorten(message, 110), transform=ax.transAxes,
                    ha="center", va="top", fontsize=6, color=DEFECT_COLOR, wrap=True)
        return ax.collections

    _save_gif(fig, FuncAnimation(fig, draw, frames=len(t), blit=False, repeat=False), out,
              fps, dpi)
    return out


def _save_gif(fig, animation, out, fps, dpi):
    """Encode ``animation`` with PillowWriter into ``out`` atomically; close ``fig``."""
    import matplotlib.pyplot as plt

    try:
        with tempfile.TemporaryDirectory() as folder:
            gif = Path(folder) / "movie.gif"      # Pillow takes the format from the suffix
            animation.save(gif, writer=PillowWriter(fps=fps), dpi=dpi)
            write_files({Path(out): gif.read_bytes()})
    finally:
        plt.close(fig)


def write_notice(out, title, status, message, size=4.0, dpi=100):
    """A one-frame GIF saying why a run has nothing to animate (e.g. its mesh was refused)."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(size, size))
    fig.text(0.5, 0.93, title, ha="center", va="top", fontsize=9)
    fig.text(0.5, 0.55, status, ha="center", va="center", fontsize=12, weight="bold",
             color=OK_COLOR if status == "ok" else DEFECT_COLOR)
    fig.text(0.5, 0.45, textwrap.fill(message, 60), ha="center", va="top", fontsize=7)
    _save_gif(fig, FuncAnimation(fig, lambda k: [], frames=1, repeat=False), out, 1, dpi)
    return Path(out)
