"""Run records: one JSON file per run, with a schema, a checksum and provenance.

A record holds every field of :class:`mcfbench.studies.RunResult` (the
problem's metrics as top-level keys), ``peak_rss_mb`` (the peak resident
memory of the process that wrote it, :func:`mcfbench.memory.peak_rss_mb`:
each job writes one record, at its end), the settings that produced it and
their provenance (:func:`mcfbench.provenance.provenance`), and a SHA-256
``checksum`` of everything else, so that a record edited by hand is refused
instead of shown in a table. NaN is stored as ``null`` (standard JSON);
records are written atomically (:mod:`mcfbench.atomic`).
"""

import hashlib
import json
from dataclasses import fields
from pathlib import Path

from .atomic import json_value, write_json
from .flow import STATUSES
from .memory import peak_rss_mb
from .provenance import config_hash, provenance
from .studies import RunResult

# field -> type of the fixed part of a record; float fields may be null (NaN)
FIELDS = {f.name: f.type for f in fields(RunResult) if f.name != "metrics"}
FIELDS.update({"peak_rss_mb": float, "settings": dict, "provenance": dict, "checksum": str})
RECOMPUTE = "delete it and run snakemake again to recompute it"


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
    record = json_value({**row, **extra, "peak_rss_mb": peak_rss_mb(),
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
        type, an unknown status, a checksum that does not match the content
        (edited by hand), or other settings; the message names the file.
    """
    record = load_json(path)
    missing = [k for k in required if k not in record]
    if missing:
        raise RecordError(f"{path}: missing key(s) {missing}; {RECOMPUTE}")
    if record["checksum"] != checksum(record):
        raise RecordError(f"{path}: checksum does not match the content (the record was "
                          f"edited or damaged); {RECOMPUTE}")
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

