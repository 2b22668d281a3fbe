"""The run store: a run is its spec, one record and one frames file per spec.

A :class:`RunSpec` holds everything that changes a run's numbers (the scheme, the
problem, the level, the time step or its rule's inputs, the final time, the solver,
the threads, the frames kept, a user's mesh file and its SHA-256), normalised so
that two studies asking for the same run build the same value. Its
:attr:`~RunSpec.key` (16 hex digits of the SHA-256 of its canonical JSON) names
its record and frames in one store, ``results/runs/{problem}/{scheme}/level{level}/
{key}.json`` and ``.npz`` (:func:`record_path`, :func:`frames_path`). Nothing parses
a path back: whoever needs the scheme reads the spec.

A record in the store carries in its ``settings`` the spec, its ``key`` and the
``code`` digest of the code that computed it (the run's code identity,
:func:`mcfbench.running.identity.identity_digest`), hashed into its provenance as
every record's settings are: :func:`stored` tells whether a record is there for a
spec and a digest (the batch job then skips the run), :func:`read_runs` reads the
records of the current specs and refuses a stale one (another key or code digest:
other settings) with a message naming it.
"""

import hashlib
import json
import math
from dataclasses import asdict, dataclass, fields
from pathlib import Path

from mcfbench.storage.records import RecordError, read_record, read_records

STORE = "results/runs"
"""The one run store."""

BATCHES = f"{STORE}/batches"
"""The batch jobs' manifests (:func:`manifest_path`): Snakemake's outputs."""

SOLVER_KEYS = ("method", "rtol", "maxiter")


@dataclass(frozen=True)
class RunSpec:
    """Everything that changes the numbers of one run.

    Attributes
    ----------
    scheme : str
        ``NAME`` or ``NAME@INTEGRATOR`` (:func:`mcfbench.running.schemes.get_scheme`).
    problem : str
        A problem of the registry, or ``"gallery"`` for a user's mesh file.
    level : int
    tau, t_final : float or None
        The time step and final time of a problem with a level rule (the
        time step resolved); None for a mesh rule, whose time step needs the mesh.
    tau_edge : float or None
        The mesh rule's ``C`` (``tau = C (mean edge length)^2``); None for a level rule.
    steps : int or None
        The mesh rule's steps; None for a level rule.
    solver : tuple of (str, value) pairs
        ``method``, ``rtol``, ``maxiter``, sorted by name (:meth:`solver_settings`).
    threads : int
    frames : int
        About how many frames the run keeps: 2 for the first and the last.
    mesh_file, mesh_sha256 : str or None
        A user's mesh file and its SHA-256 (the gallery's runs); None otherwise.
    """

    scheme: str
    problem: str
    level: int
    tau: float | None
    t_final: float | None
    tau_edge: float | None
    steps: int | None
    solver: tuple
    threads: int = 1
    frames: int = 2
    mesh_file: str | None = None
    mesh_sha256: str | None = None

    def __post_init__(self):
        level_rule = self.tau is not None and self.t_final is not None
        mesh_rule = self.tau_edge is not None and self.steps is not None
        if level_rule == mesh_rule or (level_rule and (self.tau_edge, self.steps) != (None, None)) \
                or (mesh_rule and (self.tau, self.t_final) != (None, None)):
            raise ValueError(f"run spec of {self.scheme} on {self.problem}: give tau and "
                             f"t_final (a level rule) or tau_edge and steps (a mesh rule), "
                             f"got {self.tau!r}, {self.t_final!r}, {self.tau_edge!r}, "
                             f"{self.steps!r}")
        if (self.mesh_file is None) != (self.mesh_sha256 is None):
            raise ValueError(f"run spec of {self.scheme}: a mesh file needs its SHA-256")

    @classmethod
    def make(cls, scheme, problem, level, *, solver, tau=None, t_final=None, tau_edge=None,
             steps=None, threads=1, frames=2, mesh_file=None, mesh_sha256=None):
        """The spec with every value normalised (floats, ints, the solver's settings
        sorted) so that equal runs give equal specs.

        ``solver``: a mapping with ``method``, ``rtol``, ``maxiter``.
        """
        def number(value, kind):
            if value is None:
                return None
            value = kind(value)
            if kind is float and not math.isfinite(value):
                raise ValueError(f"run spec of {scheme} on {problem}: {value!r} is not finite")
            return value

        settings = dict(solver)
        missing = [k for k in SOLVER_KEYS if k not in settings]
        if missing or set(settings) - set(SOLVER_KEYS):
            raise ValueError(f"run spec's solver: the keys {', '.join(SOLVER_KEYS)}, got "
                             f"{sorted(settings)}")
        normal = {"method": str(settings["method"]), "rtol": float(settings["rtol"]),
                  "maxiter": int(settings["maxiter"])}
        return cls(str(scheme), str(problem), int(level), number(tau, float),
                   number(t_final, float), number(tau_edge, float), number(steps, int),
                   tuple(sorted(normal.items())), int(threads), int(frames),
                   None if mesh_file is None else str(mesh_file),
                   None if mesh_sha256 is None else str(mesh_sha256))

    def solver_settings(self):
        """The solver's settings as a dict (``method``, ``maxiter``, ``rtol``)."""
        return dict(self.solver)

    def to_dict(self):
        """The spec as plain JSON values (the solver as a dict)."""
        return {**asdict(self), "solver": self.solver_settings()}

    @classmethod
    def from_dict(cls, data):
        """The spec of :meth:`to_dict` (a record's or a Snakemake param's)."""
        names = {f.name for f in fields(cls)}
        unknown = set(data) - names
        if unknown:
            raise ValueError(f"run spec: unknown key(s) {sorted(unknown)}")
        values = {k: data[k] for k in names if k in data}
        return cls.make(**values)

    @property
    def key(self):
        """16 hex digits of the SHA-256 of the spec's canonical JSON."""
        text = json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"),
                          allow_nan=False)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def record_path(spec, root=STORE):
    """``{root}/{problem}/{scheme}/level{level}/{key}.json``."""
    return f"{root}/{spec.problem}/{spec.scheme}/level{spec.level}/{spec.key}.json"


def frames_path(spec, root=STORE):
    """The frames beside the record: ``.../{key}.npz``."""
    return record_path(spec, root).removesuffix(".json") + ".npz"


def manifest_path(name, root=STORE):
    """A batch job's manifest: ``{root}/batches/{name}.json``."""
    return f"{root}/batches/{name}.json"


def store_settings(spec, digest):
    """The ``settings`` of the record of ``spec`` computed by code of ``digest``."""
    return {**spec.to_dict(), "key": spec.key, "code": digest}


def mesh_sha256(path):
    """SHA-256 of a mesh file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def stored(spec, digest, root=STORE):
    """Whether the store holds a valid record of ``spec`` by code of ``digest`` and
    its frames: the batch job then reads it instead of running the spec."""
    path = Path(record_path(spec, root))
    if not (path.is_file() and Path(frames_path(spec, root)).is_file()):
        return False
    try:
        record = read_record(path)
    except RecordError:
        return False
    settings = record["settings"]
    return settings.get("key") == spec.key and settings.get("code") == digest


def read_run(spec, digest, root=STORE):
    """The record of ``spec`` computed by code of ``digest``.

    Raises
    ------
    RecordError
        Unreadable, edited or invalid, or stale: its settings (the spec, its key,
        the code digest) are not the current ones
        (:func:`mcfbench.storage.records.read_record`); the message names the file.
    """
    return read_record(record_path(spec, root), store_settings(spec, digest))


def read_runs(specs, log=None, root=STORE):
    """The records of ``specs`` (``{spec: code digest}``), all read before any is
    refused (:func:`mcfbench.storage.records.read_records`): ``{spec: record}`` in the
    order of ``specs``.

    Raises
    ------
    RecordError
        Listing every invalid or stale record, each message naming its file.
    """
    paths = {spec: record_path(spec, root) for spec in specs}
    records = read_records({paths[spec]: store_settings(spec, digest)
                            for spec, digest in specs.items()}, log)
    return {spec: records[paths[spec]] for spec in specs}
