"""Real meshes as problems: one problem ``real_<name>`` per committed mesh.

Every mesh of :mod:`mcfbench.geometry.committed_meshes` is one problem of
:data:`mcfbench.running.problems.PROBLEMS` (declared by the problem module
:mod:`mcfbench.problems.real_meshes`), generated here from two files and
nothing else: the mesh's manifest entry and its reference answers
``mcfbench/data/meshes/references/<name>.json`` (made by
``benchmarks/real_mesh_references.py``, which names the command that remakes
them; the matrix does not recompute them). A mesh without a reference file,
or whose reference runs all broke down before ``t = tau_0`` (no checkpoint),
is not a problem.

The problem
-----------
* surface: level ``k`` of the mesh's Loop-limit series (``real_mesh``,
  :mod:`mcfbench.geometry.subdivision`): ``k`` Loop steps, every vertex at
  its limit position, so all levels sample one smooth surface;
* time step ``tau_k = 0.1 h_0^2 / 4^k`` (``h_0`` the mean edge of level 0,
  the run command's ``--tau-edge 0.1`` on level 0);
* final time ``t_final = N tau_0`` (``N <= 10``), before the flow's first
  singularity found by the reference runs;
* metric ``real_mesh`` (:class:`RealMeshShape`): the relative errors of the
  area and the enclosed volume against the reference at the checkpoints
  ``t = j tau_0``, sampled as they are reached, so they stay valid when the
  run breaks down later; and the distance of the surface at ``t_final`` to
  the reference surface there, relative to the length scale ``L = sqrt(A)``
  (``A`` the reference area at ``t_final``).

The reference surface
---------------------
``references/<name>.npz`` holds one array, ``vertices``: the positions at
``t_final`` of the finest reference run (the cotangent scheme's unless it
broke down before ``t_final``; scheme and level named in the JSON's
``distance_reference``), as float32. Its faces are
not stored: they are the level's, regenerated from the committed mesh
(:func:`mcfbench.geometry.committed_meshes.real_mesh`, deterministic), and
checked against the SHA-256 the JSON stores (:func:`reference_surface`).
float32 because its rounding, ``2^-24`` of the coordinates' magnitude,
moves the surface by less than ``1e-7 L`` on every mesh (the coordinates
stay within ``1.5 L`` of the origin), far below the distance's accuracy
(the distances between the reference runs, ``4e-5``-``2e-3 L``), and it
halves the files.
"""

import functools
import hashlib
import json
import math

import numpy as np

from mcfbench.geometry import metrics
from mcfbench.geometry.committed_meshes import MESH_DIR, mesh_manifest, real_mesh
from mcfbench.running.problem import Problem

REFERENCE_DIR = MESH_DIR / "references"
"""One ``<name>.json`` of reference answers per real mesh."""

TAU_EDGE = 0.1
"""``tau_0 = TAU_EDGE h_0^2``."""


SURFACE_DTYPE = "float32"
"""Precision of the stored reference surface (module docstring)."""


def reference_path(name):
    """The reference file of the committed mesh ``name``."""
    return REFERENCE_DIR / f"{name}.json"


def surface_path(name):
    """The reference surface's file of the committed mesh ``name``."""
    return REFERENCE_DIR / f"{name}.npz"


def faces_digest(faces):
    """SHA-256 (hex) of an ``(m, 3)`` face array as little-endian int64."""
    return hashlib.sha256(np.ascontiguousarray(faces, dtype="<i8").tobytes()).hexdigest()


@functools.lru_cache(maxsize=4)
def reference_surface(name, level, faces_sha256):
    """The stored reference surface of the committed mesh ``name``: the
    positions of :func:`surface_path` on the faces of level ``level``.

    Returns
    -------
    vertices : (n, 3) float64 array
    faces : (m, 3) int array

    Raises
    ------
    ValueError
        The file is missing, or its positions do not fit the level's vertex
        count, or the regenerated faces' SHA-256 is not ``faces_sha256`` (the
        refinement changed since the reference was made: remake it with the
        command of the reference file).
    """
    path = surface_path(name)
    if not path.is_file():
        raise ValueError(f"real mesh {name!r}: the reference surface {path} is missing")
    with np.load(path) as stored:
        V = stored["vertices"].astype(float)
    _, F = real_mesh(name, level)
    if V.shape != (int(F.max()) + 1, 3) or faces_digest(F) != faces_sha256:
        raise ValueError(f"real mesh {name!r}: {path} ({V.shape[0]} vertices) does not fit "
                         f"level {level} as regenerated now (faces' SHA-256 "
                         f"{faces_digest(F)[:12]}, stored {faces_sha256[:12]}); remake it "
                         "with the command in the reference file")
    return V, F


def real_mesh_problem(name, reference):
    """The problem ``real_<name>`` with the reference (or provisional) settings.

    Parameters
    ----------
    name : str
        A committed mesh.
    reference : dict
        At least ``h0`` (mean edge of level 0), ``steps`` (``N``),
        ``checkpoints`` (the ``j`` of ``t = j tau_0``) and ``levels``; the
        reference file adds ``area`` and ``volume`` at the checkpoints (the
        metric needs them), their accuracy, the EOCs and the singularity.

    Returns
    -------
    mcfbench.running.problem.Problem
        Of kind ``real_mesh``, main metric ``area_error``; its data files the mesh
        and the reference files (not the manifest: its other meshes' entries change
        no run of this one, and the mesh's own bytes are hashed).
    """
    entry = mesh_manifest()[name]
    tau_0 = TAU_EDGE * reference["h0"] ** 2
    singular = reference.get("singularity", {}).get("time")
    when = f"first singularity at t = {singular:.4g}" if singular is not None else \
        "no singularity before the searched time"
    return Problem(
        f"real_{name}", f"{name} ({entry['kind']}, real mesh)", "real_mesh",
        lambda level: {"mesh": name, "level": int(level)},
        levels=tuple(reference["levels"]), tau_1=tau_0 / 4.0,
        t_final=reference["steps"] * tau_0, metrics=("real_mesh",),
        exact=f"reference: finest levels of cotan and bgn ({when})",
        reference=dict(reference), kind="real_mesh", main_metric="area_error",
        data_files=(MESH_DIR / entry["file"], reference_path(name),
                    *[p for p in (surface_path(name),) if p.is_file()]),
        description=f"The {entry['kind']} mesh {entry['file']} ({entry['vertices']} vertices, "
                    f"genus {entry['genus']}; {entry['author']}), refined by Loop subdivision "
                    f"to its limit surface; tau_k = {TAU_EDGE} h_0^2 / 4^k to "
                    f"{reference['steps']} tau_0; area and volume at the checkpoints against "
                    "the reference.")


def real_mesh_problems():
    """Every committed mesh whose reference file has a checkpoint (``N >= 1``),
    as its problem: ``{"real_<name>": Problem}``."""
    problems = {}
    for name in mesh_manifest():
        path = reference_path(name)
        reference = json.loads(path.read_text()) if path.is_file() else {}
        if reference.get("steps"):
            problem = real_mesh_problem(name, reference)
            problems[problem.name] = problem
    return problems


class RealMeshShape:
    """Observer of a real-mesh problem: area and enclosed volume at the
    checkpoints ``t = j tau_0``, and their largest relative error against the
    reference (``area_error``, ``volume_error``: signed, the checkpoint of the
    largest magnitude; NaN if a checkpoint was not reached); and
    ``distance_error``, the symmetric mean distance to the reference surface
    at ``t_final`` over the length scale
    (:func:`mcfbench.geometry.surface_distance.mean_surface_distance`: the
    state at ``t_final`` is kept and measured once, by :meth:`result`, outside
    the run's timed part; NaN if not reached; absent from a reference without
    a surface, and from a run on a mesh with at least as many vertices as the
    reference surface's: a level the reference does not resolve, where the
    distance would be the scheme's difference from the reference's scheme,
    not an error). Values are kept when the run breaks down after the
    checkpoints (``keeps_before_breakdown``).
    """

    keeps_before_breakdown = True

    def __init__(self, problem):
        ref = problem.reference
        tau_0 = TAU_EDGE * ref["h0"] ** 2
        self.times = [j * tau_0 for j in ref["checkpoints"]]
        self.reference = {q: None if ref.get(q) is None else
                          [math.nan if r is None else r for r in ref[q]]
                          for q in ("area", "volume")}
        self.samples = {}
        surface = ref.get("distance_reference")
        self.surface = None if surface is None else \
            (ref["mesh"], surface["level"], surface["faces_sha256"], ref["length_scale"])
        self.surface_vertices = None if surface is None else surface["vertices"]
        self.final = None

    def __call__(self, flow):
        t = flow.n * flow.tau
        for i, tc in enumerate(self.times):
            if math.isclose(t, tc, rel_tol=1e-9, abs_tol=1e-15):
                self.samples[i] = (metrics.area(flow.vertices, flow.faces),
                                   metrics.volume(flow.vertices, flow.faces))
                if i == len(self.times) - 1:      # measured in result(), not timed
                    self.final = (np.array(flow.vertices, dtype=float), np.asarray(flow.faces))

    def values(self):
        """``{"area": [...], "volume": [...]}`` at the checkpoints (NaN where
        not reached)."""
        nan = (math.nan, math.nan)
        sampled = [self.samples.get(i, nan) for i in range(len(self.times))]
        return {"area": [a for a, _ in sampled], "volume": [v for _, v in sampled]}

    def result(self):
        out = {}
        for key, values in self.values().items():
            reference = self.reference[key]
            if reference is None:
                continue
            errors = [v / r - 1.0 for v, r in zip(values, reference)]
            worst = max(errors, key=lambda e: -1.0 if math.isnan(e) else abs(e))
            out[f"{key}_error"] = math.nan if any(map(math.isnan, errors)) else worst
        if self.surface is not None and (self.final is None
                                         or len(self.final[0]) < self.surface_vertices):
            from mcfbench.geometry.surface_distance import mean_surface_distance  # libigl

            *key, length = self.surface
            out["distance_error"] = math.nan if self.final is None else \
                mean_surface_distance(*self.final, *reference_surface(*key)) / length
        return out
