"""The gallery's pictures: per mesh the initial surface and every scheme's last frame
(:func:`gallery_grid`), and one animation per run (:func:`run_movie`)."""

from pathlib import Path

from mcfbench.presentation.picture_grid import draw_grid, last_frames, run_note
from mcfbench.presentation.plots import style as scheme_style
from mcfbench.storage.logs import setup_logging


def run_movie(record, frames, out, log_path=None):
    """The animation of one gallery run (:func:`mcfbench.presentation.movie.write_movie`),
    titled with the scheme and the mesh, the status from its record (from the step of
    the breakdown on); a run without frames (its mesh refused) gives a one-frame GIF
    with the record's message."""
    from mcfbench.presentation.movie import write_movie, write_notice
    from mcfbench.running.schemes import scheme_label
    from mcfbench.storage.frames import load_frames
    from mcfbench.storage.records import read_record

    log = setup_logging(log_path)
    data = read_record(record)
    scheme = scheme_label(data["scheme"])
    title = f"{scheme} on {data.get('mesh', Path(frames).parent.name)}"
    arrays = load_frames(frames)
    if not len(arrays["t"]):
        write_notice(out, title, data["status"], data["message"])
        log.info("%s: no frames (%s) -> %s", title, data["status"], out)
        return
    failed = data.get("t_failed")
    failed_step = -1 if data["status"] == "ok" or failed is None else \
        round(failed / data["tau"])
    write_movie({**arrays, "status": data["status"], "message": data["message"],
                 "failed_step": failed_step}, out, title=title)
    log.info("%s: %d frames, %s -> %s", title, len(arrays["t"]), data["status"], out)


GRID_COLUMNS = 6
"""At most this many pictures a line of the gallery's grid: a mesh's initial surface and
every scheme's last frame wrap onto lines of equal length (12.2 in wide at most, a
laptop page's column at print size)."""


def gallery_grid(entries, paths, meshes, schemes):
    """Per mesh the initial surface and each scheme's last frame, in lines of at most
    :data:`GRID_COLUMNS` pictures.

    ``entries``: ``(mesh, scheme) -> (record, frames)``.
    """
    cells = last_frames(entries, meshes, schemes, run_note,
                        lambda record, faces: f"{len(faces)} triangles")
    labels = ["initial"] + [scheme_style(s)[0] for s in schemes]
    draw_grid(cells, list(meshes), labels, paths, "Gallery: first and last frame per scheme",
              share="row", max_cols=GRID_COLUMNS)
