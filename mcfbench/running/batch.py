"""Runs of the run store: a spec made from a problem's rule (:func:`spec_of`), one
spec run into its record and frames (:func:`run_spec`) and a batch of them in one
process (:func:`run_batch`, the one Snakemake job of every study's runs).

Every run is :func:`mcfbench.running.run.framed_run`, continued with the scheme's
robust solver when it ends with a ``solver_*`` status (the record's ``robust_*``
keys, :func:`robust_fields`). Its record (:func:`mcfbench.storage.records.write_record`)
carries the spec, its key and the digest of the run's code identity
(:func:`mcfbench.running.identity.identity_digest`); its frames (the first and the
last, or about ``spec.frames``) carry the final state's quadrature weights
``l2_weights`` (``flow.l2_weights``) when it finished, so that a view comparing
final states needs no solver. A batch skips every spec whose record is in the
store with the same key and code digest (read, not rewritten) and writes a
manifest of the batch (keys, paths, digests, statuses).
"""

import logging
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from mcfbench.running.problems import Problem, get_problem
from mcfbench.running.schemes import get_scheme
from mcfbench.storage import run_store
from mcfbench.storage.atomic import write_json
from mcfbench.storage.logs import setup_logging

GALLERY_PROBLEM = "gallery"
"""The problem name of a user's mesh file (:func:`mesh_spec`)."""


def spec_of(scheme, problem, level, *, solver, tau=None, t_final=None, threads=1, frames=2):
    """The :class:`~mcfbench.storage.run_store.RunSpec` of ``scheme`` on the registry's
    ``problem`` at ``level``: a level rule's time step resolved (``tau``, ``t_final``
    default to the problem's), a mesh rule's inputs (``tau_edge``, ``steps``) kept.

    ``solver``: a mapping with ``method``, ``rtol``, ``maxiter``.
    """
    entry = get_problem(problem)
    if entry.tau_rule == "mesh":
        return run_store.RunSpec.make(scheme, entry.name, level, solver=solver,
                                      tau_edge=entry.tau_1, steps=entry.steps,
                                      threads=threads, frames=frames)
    return run_store.RunSpec.make(
        scheme, entry.name, level, solver=solver,
        tau=entry.tau(level) if tau is None else tau,
        t_final=entry.t_final if t_final is None else t_final, threads=threads, frames=frames)


def mesh_spec(scheme, mesh_file, sha256, *, tau_edge, steps, solver, frames):
    """The spec of ``scheme`` on a user's mesh file: ``tau = tau_edge (mean edge
    length)^2``, ``steps`` steps (the gallery's runs)."""
    return run_store.RunSpec.make(scheme, GALLERY_PROBLEM, 1, solver=solver,
                                  tau_edge=tau_edge, steps=steps, frames=frames,
                                  mesh_file=mesh_file, mesh_sha256=sha256)


def save_every(spec, steps):
    """The driver's ``save_every`` of a spec: 0 keeps the first and the last frame,
    else every ``steps // frames``-th step."""
    return 0 if spec.frames <= 2 else max(1, steps // spec.frames)


def run_spec(spec):
    """Run one spec.

    Returns
    -------
    result : RunResult
    frames : dict of arrays
        :mod:`mcfbench.storage.frames`' layout, with ``l2_weights`` of the final state
        when the run finished.
    robust : RunResult or None
        The robust continuation (:func:`mcfbench.running.run.run`'s ``robust``).
    extra : dict
        More keys of the record (a user's mesh: ``mesh``, ``intake``).
    """
    from mcfbench.running.run import failed_result, final_weights, framed_run
    from mcfbench.running.solver import Solver

    scheme = get_scheme(spec.scheme)
    solver = Solver(**spec.solver_settings())
    robust = replace(solver, method=scheme.robust_solver)
    extra, mesh, tau = {}, None, spec.tau
    if spec.mesh_file is not None:
        problem = Problem.user_mesh("a user's mesh", spec.steps, spec.tau_edge,
                                    name=GALLERY_PROBLEM)
        extra["mesh"] = Path(spec.mesh_file).name
        mesh, tau, refused = _user_mesh(spec)
        if refused is not None:
            result = failed_result(scheme, problem, spec.level, "unsupported",
                                   f"unsupported at step 0 (t = 0): the mesh was refused: "
                                   f"{refused}", steps=spec.steps, method=solver.method)
            return result, {"faces": np.zeros((0, 3), int), "steps": np.zeros(0, int),
                            "t": np.zeros(0)}, None, extra
        extra["intake"] = mesh[2]
        mesh = mesh[:2]
        steps = spec.steps
    elif spec.tau_edge is not None:
        problem = get_problem(spec.problem).with_settings(tau_1=spec.tau_edge, steps=spec.steps)
        steps = spec.steps
    else:
        problem = get_problem(spec.problem).with_settings(t_final=spec.t_final)
        steps = problem.time_steps(spec.tau, spec.t_final)
    options = {} if spec.t_final is None else {"t_final": spec.t_final}
    result, frames, continued = framed_run(
        scheme, problem, spec.level, solver=solver, mesh=mesh, tau=tau,
        save_every=save_every(spec, steps), robust=robust, threads=spec.threads, **options)
    # the time study's weights, of a run that kept its mesh (a remeshed or cut run's
    # last state is on another mesh); a last state the scheme refuses (a component
    # that vanished, its points frozen) has none, which the time study names
    if result.status == "ok" and scheme.mesh_strategy == "none":
        try:
            frames["l2_weights"] = final_weights(scheme, frames)
        except ValueError:
            pass
    return result, frames, continued, extra


def _user_mesh(spec):
    """``((V, F, intake notes), tau, None)`` of a spec's mesh file, or ``(None, None,
    message)`` when the reader refuses it; the file's SHA-256 checked first. The file
    is read once per process (:data:`_read_meshes`; copies given): a survival batch
    runs every scheme on one file (57 reads of the same file, each a forked libigl
    reader and the intake's repairs and validation)."""
    from mcfbench.geometry import metrics

    digest = run_store.mesh_sha256(spec.mesh_file)
    if digest != spec.mesh_sha256:
        raise ValueError(f"{spec.mesh_file}: SHA-256 {digest} is not the spec's "
                         f"{spec.mesh_sha256}: the file changed after the plan was made")
    key = (str(Path(spec.mesh_file).resolve()), digest)
    if key not in _read_meshes:
        _read_meshes.clear()                    # a batch's runs share one file
        _read_meshes[key] = _read(spec.mesh_file)
    read = _read_meshes[key]
    if isinstance(read, str):
        return None, None, read
    V, F, notes = read
    return ((V.copy(), F.copy(), list(notes)),
            spec.tau_edge * metrics.mean_edge_length(V, F) ** 2, None)


_read_meshes = {}
"""(resolved path, SHA-256) -> ``(V, F, intake notes)`` or the reader's refusal: the
last mesh file read in this process (:func:`_user_mesh`)."""


def _read(path):
    """``(V, F, intake notes)`` of a mesh file, or the reader's refusal (str)."""
    from mcfbench.geometry.mesh_files import read_mesh

    try:
        V, F, report = read_mesh(path)
    except ValueError as err:
        return str(err)
    return V, F, report.notes()


def robust_fields(robust):
    """The record's keys of the robust re-run (None: there was none):
    ``robust_status`` (``""`` without a re-run), ``robust_solver``, ``robust_message``,
    ``robust_t_failed``, ``robust_steps_done``, ``robust_iterations`` (of the whole
    run: the failed solver's steps before the failure and the robust solver's
    after), ``robust_cpu_seconds`` (the continuation's after the failure: what the
    robust solver cost beyond the run) and ``robust_metrics`` (metric -> value, NaN
    unless it finished)."""
    if robust is None:
        return {"robust_status": ""}
    return {"robust_status": robust.status, "robust_solver": robust.solver,
            "robust_message": robust.message, "robust_t_failed": robust.t_failed,
            "robust_steps_done": robust.steps_done, "robust_iterations": robust.iterations,
            "robust_cpu_seconds": robust.cpu_seconds, "robust_metrics": dict(robust.metrics)}


def compute(spec, digest, root=run_store.STORE, log=None):
    """Run ``spec`` and write its frames, then its record (both atomically; the record
    last: a record in the store always has its frames).

    Returns
    -------
    dict
        The record as written.
    """
    from mcfbench.storage.frames import save_frames
    from mcfbench.storage.records import write_record

    log = log or logging.getLogger("pipeline")
    log.info("%s on %s level %d (%s), solver %s", spec.scheme, spec.problem, spec.level,
             spec.key, spec.solver_settings()["method"])
    result, frames, robust, extra = run_spec(spec)
    save_frames(run_store.frames_path(spec, root), frames)
    path = run_store.record_path(spec, root)
    record = write_record(path, result, run_store.store_settings(spec, digest),
                          metric_names=list(result.metrics), **robust_fields(robust), **extra)
    log.info("%s; %d/%d steps, %s, %.1f s CPU -> %s", result.status, result.steps_done,
             result.N, ", ".join(f"{k} {v:.4g}" for k, v in result.metrics.items()),
             result.cpu_seconds, path)
    if result.status != "ok":
        log.warning("%s", result.message)
    if robust is not None:
        log.info("continued with %s from step %d: %s%s, %.1f s CPU", robust.solver,
                 result.steps_done, robust.status,
                 f" ({robust.message})" if robust.message else "", robust.cpu_seconds)
    return record


def run_batch(entries, manifest, log_path=None, root=run_store.STORE):
    """The Snakemake job of one batch: every spec of ``entries`` whose record is not
    in the store with the same key and code digest is run (:func:`compute`), the
    others are left as they are; then the batch's manifest is written.

    Parameters
    ----------
    entries : list of dict
        ``spec`` (:meth:`RunSpec.to_dict`) and ``code`` (its digest), in run order.
    manifest : str or Path
        The batch's manifest: per spec its ``key``, ``record``, ``frames``, ``code``,
        ``status`` and whether it was ``computed`` here.
    log_path : str, optional

    Returns
    -------
    dict
        The manifest.
    """
    log = setup_logging(log_path) if log_path else logging.getLogger("pipeline")
    start, runs = time.perf_counter(), []
    for entry in entries:
        spec = run_store.RunSpec.from_dict(entry["spec"])
        computed = not run_store.stored(spec, entry["code"], root)
        if computed:
            record = compute(spec, entry["code"], root, log)
        else:
            record = run_store.read_run(spec, entry["code"], root)
            log.info("%s on %s level %d (%s): in the store", spec.scheme, spec.problem,
                     spec.level, spec.key)
        runs.append({"key": spec.key, "record": run_store.record_path(spec, root),
                     "frames": run_store.frames_path(spec, root), "code": entry["code"],
                     "status": record["status"], "computed": computed})
    data = {"runs": runs, "computed": sum(r["computed"] for r in runs),
            "seconds": time.perf_counter() - start}
    write_json(manifest, data)
    log.info("%d runs, %d computed, %d in the store -> %s", len(runs), data["computed"],
             len(runs) - data["computed"], manifest)
    return data
