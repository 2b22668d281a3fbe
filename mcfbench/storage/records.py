"""Run records: one JSON file per run, with a schema, a checksum and provenance.

A record holds every field of :class:`mcfbench.storage.records.RunResult` (the
problem's metrics as top-level keys), ``peak_rss_mb`` (the peak resident
memory of the process that wrote it, :func:`mcfbench.storage.memory.peak_rss_mb`:
each job writes one record, at its end), the settings that produced it and
their provenance (:func:`mcfbench.storage.provenance.provenance`), and a SHA-256
``checksum`` of everything else, so that a record edited by hand is refused
instead of shown in a table. NaN is stored as ``null`` (standard JSON);
records are written atomically (:mod:`mcfbench.storage.atomic`). A record
carries ``format_version`` (:data:`FORMAT_VERSION`); a record without it is read
as before (version 0), a newer one is refused. Every change of the keys is listed
in ``docs/formats.md``.
"""

import hashlib
import json
from dataclasses import MISSING, asdict, dataclass, field, fields
from pathlib import Path

from mcfbench.storage.atomic import json_value, write_json
from mcfbench.storage.frames import check_version
from mcfbench.storage.memory import peak_rss_mb
from mcfbench.storage.provenance import config_hash, provenance
from mcfbench.storage.statuses import STATUSES


@dataclass
class RunResult:
    """One scheme on one problem at one level.

    Attributes
    ----------
    scheme, problem : str
    level : int
    nV : int
        Points of the state (DDFV: F- plus T-vertices).
    nF, nT : int
        Mesh vertices and triangles.
    h : float
        Mean edge length of the initial mesh.
    tau : float
    N : int
        Steps asked for.
    steps_done : int
        Steps completed.
    status, message : str
        ``"ok"`` or the breakdown (:data:`mcfbench.storage.statuses.STATUSES`).
    t_failed : float
        Time of the breakdown or first defect, NaN when ``ok``.
    t_end : float
        Time of the last state reached (earlier than ``N tau`` at a
        breakdown or when the steady state was reached).
    steady : bool
        The run stopped at the problem's steady state.
    iterations : int
        Total solver iterations.
    solver : str
        The solver's method.
    integrator : str
        The time integrator (:data:`mcfbench.running.integrators.INTEGRATORS`).
    cpu_seconds, wall_seconds : float
        Flow construction (T-vertex initialisation included), stepping and
        metrics, the warm-up left out (compilation, first calls:
        :func:`mcfbench.running.run.warm_up`); the best of ``timing_repeats``
        executions.
    t_min_barycentric : float
        DDFV: the T monitor, smallest barycentric coordinate of a T-vertex
        over all time levels reached (NaN for the other schemes).
    min_angle, max_aspect, max_flipped : float
        Worst mesh quality over the sampled time levels
        (:func:`mcfbench.geometry.metrics.quality`).
    metrics : dict
        The problem's metrics (e.g. ``l2_error``); NaN when the run did not
        finish.
    series : dict of lists
        ``t``, ``t_min_barycentric`` (every level), ``quality_t``,
        ``min_angle``, ``max_aspect``, ``flipped``, ``covolume_ratio``
        (sampled levels; :func:`mcfbench.geometry.metrics.covolume_ratio` of the
        scheme's own covolumes, absent from records written before it).
    timing_repeats : int
        How many executions of the run ``cpu_seconds`` and ``wall_seconds`` are
        the best of: 1, or more for a run too short to time once (below
        :data:`mcfbench.running.run.SHORT_RUN` CPU seconds), as :mod:`timeit`
        does. Optional in a record (:data:`DEFAULTS`): records written before
        it existed read as 1.
    removed_area_share : float
        The area a ``NAME+surgery`` run's neck cuts removed over its initial area
        (0 without one; :mod:`mcfbench.running.continuation`).
    surgery_exceeded : bool
        Its cuts removed more than
        :data:`mcfbench.running.continuation.MAX_REMOVED_SHARE` of the area: the run
        does not count as reaching its end, whatever its status. Both optional in a
        record (:data:`DEFAULTS`): 0 and False before they existed.
    rollbacks : int
        The steps that folded and were rolled back (a mesh strategy's second chance:
        the run's ``rolled_back`` events, :mod:`mcfbench.running.rollback`); 0 for a
        run without a mesh strategy. Optional in a record: 0 before it existed.
    """

    scheme: str
    problem: str
    level: int
    nV: int
    nF: int
    nT: int
    h: float
    tau: float
    N: int
    steps_done: int
    status: str
    message: str
    t_failed: float
    t_end: float
    steady: bool
    iterations: int
    solver: str
    integrator: str
    cpu_seconds: float
    wall_seconds: float
    t_min_barycentric: float
    min_angle: float
    max_aspect: float
    max_flipped: float
    metrics: dict = field(default_factory=dict)
    series: dict = field(default_factory=dict, repr=False)
    timing_repeats: int = 1
    removed_area_share: float = 0.0
    surgery_exceeded: bool = False
    rollbacks: int = 0

    def to_dict(self, series=True):
        """Fields as a flat dict: the metrics as top-level keys; ``series=False``
        leaves out the time series."""
        row = asdict(self)
        row.update(row.pop("metrics"))
        if not series:
            del row["series"]
        return row


# field -> type of the fixed part of a record; float fields may be null (NaN)
FIELDS = {f.name: f.type for f in fields(RunResult) if f.name != "metrics"}
FIELDS.update({"peak_rss_mb": float, "settings": dict, "provenance": dict, "checksum": str,
               "format_version": int})
DEFAULTS = {f.name: f.default for f in fields(RunResult) if f.default is not MISSING}
DEFAULTS["format_version"] = 0
"""Fields a record may lack (written before they existed) -> the value they read as."""
RECOMPUTE = "delete it and run snakemake again to recompute it"

FORMAT_VERSION = 1
"""The version of the record :func:`write_record` writes (``docs/formats.md``); a
record without the key reads as version 0."""


class RecordError(ValueError):
    """A record that cannot be used; the message names the file."""


def checksum(record):
    """SHA-256 of a record without its ``checksum`` key (canonical JSON)."""
    body = {k: v for k, v in record.items() if k != "checksum"}
    text = json.dumps(json_value(body), sort_keys=True, allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def write_record(path, result, settings, **extra):
    """Write the record of ``result`` (a :class:`RunResult` or a dict) atomically,
    with the peak resident memory of this process so far (``peak_rss_mb``).

    Parameters
    ----------
    path : str or Path
    result : RunResult or dict
    settings : dict
        What produced it; stored, hashed into the provenance.
    **extra
        More top-level keys.

    Returns
    -------
    dict
        The record as written.
    """
    row = result.to_dict() if isinstance(result, RunResult) else dict(result)
    record = json_value({**row, **extra, "format_version": FORMAT_VERSION,
                         "peak_rss_mb": peak_rss_mb(),
                         "settings": settings, "provenance": provenance(settings)})
    record["checksum"] = checksum(record)
    write_json(path, record)
    return record


def load_json(path, what="record"):
    """Read a JSON object; RecordError naming the file when it cannot be read."""
    try:
        text = Path(path).read_text()
    except OSError as err:
        raise RecordError(f"{path}: cannot read {what}: {err}") from None
    try:
        record = json.loads(text)
    except json.JSONDecodeError as err:
        raise RecordError(f"{path}: not valid JSON ({err}); {RECOMPUTE}") from None
    if not isinstance(record, dict):
        raise RecordError(f"{path}: expected a JSON object, got {type(record).__name__}; "
                          f"{RECOMPUTE}")
    return record


def read_record(path, settings=None, required=FIELDS):
    """Read and check one record.

    Parameters
    ----------
    path : str or Path
    settings : dict, optional
        The settings the record must come from (a stale record, whose
        settings hash differs, is refused).
    required : dict
        Key -> type of the keys that must be present (default: a run record).

    Returns
    -------
    dict
        The record, null floats as NaN.

    Raises
    ------
    RecordError
        Unreadable or invalid JSON, a missing key, a value of the wrong
        type, an unknown status, a ``format_version`` newer than
        :data:`FORMAT_VERSION`, a checksum that does not match the content
        (edited by hand), or other settings; the message names the file.
    """
    record = load_json(path)
    try:
        check_version(record.get("format_version", 0), FORMAT_VERSION, path, "run record")
    except ValueError as err:
        raise RecordError(str(err)) from None
    missing = [k for k in required if k not in record and k not in DEFAULTS]
    if missing:
        raise RecordError(f"{path}: missing key(s) {missing}; {RECOMPUTE}")
    if record["checksum"] != checksum(record):
        raise RecordError(f"{path}: checksum does not match the content (the record was "
                          f"edited or damaged); {RECOMPUTE}")
    record = {**{k: v for k, v in DEFAULTS.items() if k in required}, **record}
    for key, kind in required.items():
        value = record[key]
        if kind is float:
            ok = value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))
        elif kind is int:
            ok = isinstance(value, int) and not isinstance(value, bool)
        else:
            ok = isinstance(value, kind)
        if not ok:
            raise RecordError(f"{path}: key {key!r} should be {kind.__name__}"
                              f"{' or null' if kind is float else ''}, got {value!r}; "
                              f"{RECOMPUTE}")
    if "status" in record and record["status"] not in STATUSES:
        raise RecordError(f"{path}: unknown status {record['status']!r} (expected one of "
                          f"{', '.join(STATUSES)}); {RECOMPUTE}")
    if settings is not None and record["provenance"].get("config_hash") != config_hash(settings):
        raise RecordError(f"{path}: its settings are not the current ones (hash "
                          f"{record['provenance'].get('config_hash')!r}, expected "
                          f"{config_hash(settings)!r}): the record is stale; {RECOMPUTE}")
    return {k: (float("nan") if v is None and required.get(k, float) is float else v)
            for k, v in record.items()}


def read_records(expected, log=None, required=None):
    """Read and check every record of ``expected`` (``{path: settings}``), all of
    them before refusing any: the one reader of every aggregation.

    Parameters
    ----------
    expected : dict
        Record path -> the settings it must come from (stale records are refused).
    log : logging.Logger, optional
        Each invalid record is logged as an error.
    required : callable, optional
        ``required(settings)`` -> the keys and types a record of those settings
        must have (default: a run record, :data:`FIELDS`).

    Returns
    -------
    dict
        ``{path: record}`` in the order of ``expected``.

    Raises
    ------
    RecordError
        Listing every invalid record, each message naming its file.
    """
    records, errors = {}, []
    for path, settings in expected.items():
        try:
            records[path] = read_record(path, settings,
                                        required=FIELDS if required is None else required(settings))
        except RecordError as err:
            errors.append(str(err))
            if log is not None:
                log.error("invalid run record: %s", err)
    if errors:
        raise RecordError(f"aggregation stopped: {len(errors)} invalid run record(s):\n"
                          + "\n".join(errors))
    return records

