"""The run store's Snakemake jobs: the specs every study asks for gathered into
batches (:func:`batches`), each one process that runs its specs one after the
other (:func:`mcfbench.running.batch.run_batch`).

A spec two studies ask for is in exactly one batch. The specs are grouped by
problem and by the studies that ask for them (a study's target then runs no
batch of specs that only others asked for), then into series (one scheme; a user's
mesh file: one scheme on it, the file's schemes one after the other), and the
series packed by their estimated cost (:func:`spec_seconds`, :func:`pack` by
:data:`BATCH_SECONDS`), a heavy one alone.
Which batch a run falls in does not decide whether it is computed: a batch
reads the runs that the store holds with the same spec key and code digest.
"""

import os
from dataclasses import dataclass

from mcfbench.running.batch import GALLERY_PROBLEM

RUN_SECONDS = 0.3
"""Estimated CPU seconds of a run besides its time steps (:func:`spec_seconds`):
its mesh, its share of the scheme's warm-up, the metrics, the record and frames
written (measured 2026-11-26: a cut-down matrix of 198 runs in 8 batch jobs took
64 CPU s besides the kernels' compilation and the tables and figures: 18 s the
runs' timed flows, the other 46 s (the processes' start-up and Snakemake's work
included) 0.23 s a run)."""

BATCH_SECONDS = 60.0
"""Estimated CPU seconds of work a batch gathers at least (:func:`batches`). A job
costs about 1.7 s besides its runs (the process's start-up, the harness's imports,
Snakemake's work; and 0.14 s a series, 0.02 s a run: fitted to the 127 jobs of the
full matrix of 2026-11-26, f699a17, their benchmark wall times against their
records' times). The jobs of that matrix replayed on 2 cores
(``benchmarks/matrix_batches.py``, the records' CPU seconds, costliest estimate
first) end the runs after 1 083 s with a 10 s budget (169 jobs), 1 009 s with 30 s
(82), 984 s with 60 s (53) and 977 s with 90 s (44), the two cores within 2 s of
each other in each: 60 s takes most of the gain and keeps a killed job's loss and a
process's memory small."""

MATRIX_FACTORS = {"ddfv": 3.7, "ddfv, redistributing": 0.51, "vertex": 2.6,
                  "vertex, redistributing": 0.14, "bgn": 7.1, "kll": 2.6}
"""Kind of scheme (:func:`mcfbench.running.cost.cost_class`) -> the measured CPU
seconds of a matrix series over the cost model's estimate (:func:`spec_seconds`):
the median over the series of the full matrix of 2026-11-26 (f699a17) above 0.3 s
(149, 56, 142, 20, 23, 16 series; ``benchmarks/matrix_batches.py``). The model
was fitted to steps of the sphere (:data:`mcfbench.running.cost.COSTS`); the
matrix's series take more solver iterations a step (larger steps, real meshes,
the anisotropic sphere) and the redistributing ones mostly stop early. Within a
kind, a series is still within a factor 2.5 of its measured time in the median,
a factor 7-15 in one case out of ten; the factor brings the heavy series out (1 for
a kind not measured: ``"dual-mdr"`` and ``"ddfv, tangential"``, kinds since
2026-12-07, whose series that matrix counted with ``"vertex"`` and ``"ddfv"``; their
own time fits are 4.7 and 2.8 x those kinds' at level 5)."""


MESH_FILE_SECONDS = 9.0
"""Estimated CPU seconds of a run on a user's mesh file per megabyte of the file
(:func:`spec_seconds`): the survival study's runs (every scheme, ``+remesh``,
``+surgery``) took 1.30 s a run on ``cowhead`` (0.23 MB, 4 537 vertices: 5.7 s/MB),
2.5 s on ``blub_open`` (0.29 MB, 5 857 vertices: 8.5 s/MB) and 9.9 s on ``face``
(0.86 MB, 17 157 vertices, its first 36 runs: 11.6 s/MB; its remeshed runs 11-15 s),
0.02-0.13 s on the files below 0.06 MB (230855d, 2026-12-08). A file's size follows
its vertex count within a factor 5 over the raw corpus (37-270 bytes a vertex): it
tells the heavy files, whose runs fill several batches that the two cores share,
from the light ones, packed together (before, one batch per file, all of equal
priority: ``face``'s 57 runs, about 9 CPU minutes, one job, started whenever
Snakemake chose)."""


def spec_seconds(spec):
    """Estimated CPU seconds of one spec: :data:`RUN_SECONDS` and the time steps' CPU
    seconds of the cost model (:func:`mcfbench.running.cost.estimate`; the problem's
    first level is built once per process to know its size) times the factor of the
    scheme's kind (:data:`MATRIX_FACTORS`). The order of magnitude only: it tells the
    heavy series from the cheap ones. A user's mesh file (not read while planning)
    counts by its size, :data:`MESH_FILE_SECONDS` a megabyte (:data:`BATCH_SECONDS`
    when it cannot be found)."""
    from mcfbench.running.cost import cost_class, estimate, size
    from mcfbench.running.problems import get_problem
    from mcfbench.running.schemes import get_scheme

    if spec.problem == GALLERY_PROBLEM:
        try:
            megabytes = os.path.getsize(spec.mesh_file) / 1e6
        except (OSError, TypeError):
            return BATCH_SECONDS
        return RUN_SECONDS + MESH_FILE_SECONDS * megabytes
    entry, problem = get_scheme(spec.scheme), get_problem(spec.problem)
    if spec.tau_edge is not None:
        problem = problem.with_settings(tau_1=spec.tau_edge, steps=spec.steps)
    factor = MATRIX_FACTORS.get(cost_class(entry), 1.0)
    return RUN_SECONDS + factor * estimate(
        entry, *size(entry, problem, spec.level, tau=spec.tau, t_final=spec.t_final)).seconds


@dataclass(frozen=True)
class Batch:
    """The specs that one Snakemake job runs in one process.

    Attributes
    ----------
    name : str
        ``{problem}_{studies}_batch{k}`` (the rule's and the manifest's name).
    problem : str
    studies : tuple of str
        The studies that ask for every spec of the batch.
    specs : tuple of RunSpec
        Run order: series after series, each in the order asked.
    seconds : float
        Their estimated CPU seconds.
    """

    name: str
    problem: str
    studies: tuple
    specs: tuple
    seconds: float


def batches(requests, cost=spec_seconds):
    """The specs of ``requests`` gathered into batches.

    Parameters
    ----------
    requests : dict
        Study -> its specs (in its order; a spec may be asked for by several studies).
    cost : callable
        Spec -> estimated CPU seconds.

    Returns
    -------
    list of Batch
        Deterministic for the same requests; every spec in exactly one batch.
    """
    askers = {}
    for study, specs in requests.items():
        for spec in specs:
            askers.setdefault(spec, [])
            if study not in askers[spec]:
                askers[spec].append(study)
    groups = {}          # (problem, studies) -> series key -> specs
    for spec, studies in askers.items():
        series = spec.scheme if spec.mesh_file is None else (spec.mesh_file, spec.scheme)
        groups.setdefault((spec.problem, tuple(sorted(studies))), {}).setdefault(
            series, []).append(spec)
    out = []
    for (problem, studies), series in groups.items():
        seconds = {name: sum(cost(s) for s in specs) for name, specs in series.items()}
        for k, group in enumerate(pack(seconds, BATCH_SECONDS), start=1):
            out.append(Batch(f"{problem}_{'-'.join(studies)}_batch{k}", problem, studies,
                             tuple(s for name in group for s in series[name]),
                             sum(seconds[name] for name in group)))
    return out


def pack(costs, budget):
    """Consecutive groups of the keys of ``costs`` (in its order), each closed when its
    costs reach ``budget``; a key costing ``budget`` or more is alone.

    Parameters
    ----------
    costs : dict
        Name -> estimated cost.
    budget : float

    Returns
    -------
    list of list
        Every key in exactly one group, in order but for the heavy ones, each alone
        where it comes.
    """
    groups, group, total = [], [], 0.0
    for name, cost in costs.items():
        if cost >= budget:
            groups.append([name])
            continue
        group.append(name)
        total += cost
        if total >= budget:
            groups.append(group)
            group, total = [], 0.0
    return groups + [group] if group else groups
