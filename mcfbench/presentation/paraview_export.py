"""A run's frames as a ParaView collection (``mcfbench run --out NAME.pvd``, ``mcfbench export``).

Reads the frames a run kept (the ``run`` command's ``.npz``, or a frames
file of the matrix or the gallery, :func:`mcfbench.running.run.framed_run`:
``vertices``, DDFV's ``extra_points``, ``faces``, ``t``) and writes one ``.vtu`` per frame
and part through :func:`mcfbench.storage.paraview.write_pvd`:

``surface``
    The triangle mesh (DDFV: the F-vertices) with the point fields
    ``displacement`` (since the previous frame) and ``vertex_area`` (vertex
    schemes) or ``covolume`` (DDFV), and for DDFV the cell field
    ``t_monitor`` per triangle (:mod:`mcfbench.geometry.frame_fields`).
``t_vertices`` (DDFV only)
    The T-vertices as a point cloud (one vertex cell each) with
    ``displacement``, ``covolume`` and ``t_monitor``.

The collection carries the provenance: that of the run (the ``.npz``'s own,
or the record next to a matrix or gallery frames file,
``.../frames/X/Y.npz`` -> ``.../runs/X/Y.json``), its scheme, status and
message when known, and that of the export.
"""

import json
from pathlib import Path

import numpy as np

from mcfbench.geometry.frame_fields import ddfv_frame_fields, vertex_frame_fields
from mcfbench.storage.frames import load_frames, mesh_segments
from mcfbench.storage.paraview import Piece, write_pvd
from mcfbench.storage.provenance import provenance
from mcfbench.storage.records import load_json

RUN_KEYS = ("scheme", "status", "message", "failed_step")
"""Scalars of a run ``.npz`` copied into the collection's provenance."""


def load_frames_file(path):
    """The arrays of a run's frames file (:func:`mcfbench.storage.frames.load_frames`),
    checked for frames to export.

    Raises
    ------
    ValueError
        Not a frames file, or no frame (a gallery run whose mesh was refused); the
        message names the file.
    """
    arrays = load_frames(path)
    if len(arrays["t"]) == 0:
        raise ValueError(f"{path}: the run has no frames (its mesh was refused; see its record)")
    return arrays


def run_pieces(arrays):
    """The parts of every frame of a run.

    Parameters
    ----------
    arrays : dict
        A run's frames (:func:`~mcfbench.storage.frames.mesh_segments`: a DDFV run's
        T-vertices as their own piece; a remeshed run's frames each with its faces,
        the displacements since the last remesh).

    Returns
    -------
    list of dict of str -> mcfbench.storage.paraview.Piece
        Per frame: ``surface`` (and ``t_vertices`` for DDFV).
    """
    pieces = []
    for faces, V, T in mesh_segments(arrays):    # a remeshed run: displacements per mesh
        faces, V = np.asarray(faces, dtype=np.int64), np.asarray(V, dtype=np.float64)
        if T is None:
            pieces += [{"surface": Piece(V[k], faces, point_data)}
                       for k, point_data in enumerate(vertex_frame_fields(V, faces))]
            continue
        T = np.asarray(T, dtype=np.float64)
        single = np.arange(len(faces))[:, None]
        pieces += [{"surface": Piece(V[k], faces, fields["vertices"], fields["triangles"]),
                    "t_vertices": Piece(T[k], single, fields["extra_points"])}
                   for k, fields in enumerate(ddfv_frame_fields(V, T, faces))]
    return pieces


def run_provenance(arrays, source=None):
    """What the collection (and the animation) says of the run: its scheme,
    status, message and failed step (:data:`RUN_KEYS`), and its provenance (the
    ``.npz``'s, or that of the record next to a matrix or gallery frames file
    ``source``, whose ``t_failed / tau`` is the failed step)."""
    run = {key: arrays[key].item() for key in RUN_KEYS if key in arrays}
    if "provenance" in arrays:
        run["provenance"] = json.loads(arrays["provenance"].item())
    elif source is not None:
        record = sibling_record(source)
        if record is not None:
            data = load_json(record)
            run.update({key: data[key] for key in ("scheme", "status", "message", "settings",
                                                   "provenance") if key in data})
            if data.get("t_failed") is not None and data.get("tau"):
                # the time level of the breakdown or first defect, as a run .npz has it
                run["failed_step"] = round(data["t_failed"] / data["tau"])
            run["record"] = record.as_posix()
    return run


def sibling_record(frames_path):
    """The record of a run store's frames file (``{key}.npz`` -> ``{key}.json`` beside
    it, :mod:`mcfbench.storage.run_store`), or None when there is none."""
    record = Path(frames_path).with_suffix(".json")
    return record if record.is_file() else None


def export_pvd(arrays, out, run=None, config=None):
    """Write the frames ``arrays`` of a run as the collection ``out`` (``.pvd``).

    Parameters
    ----------
    arrays : dict
        As :func:`run_pieces`, with ``t`` (frames,).
    out : str or Path
    run : dict, optional
        The run's provenance and status (:func:`run_provenance`).
    config : dict, optional
        Settings of the export, in its provenance.

    Returns
    -------
    list of Path
        The files written, the ``.pvd`` last.
    """
    return write_pvd(out, run_pieces(arrays), arrays["t"],
                     provenance={"run": run or {}, "export": provenance(config or {})})


def export_file(source, out):
    """Convert an existing run ``.npz`` (:func:`load_frames_file`) to the collection ``out``."""
    arrays = load_frames_file(source)
    return export_pvd(arrays, out, run_provenance(arrays, source),
                      {"command": "export", "source": str(source)})
