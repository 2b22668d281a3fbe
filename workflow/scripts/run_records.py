"""Run records: one JSON file per (scheme, level).

A record holds every field of :class:`ddfv.sphere.SphereRun`, the scheme,
its module and options, ``t_final``, ``rtol`` and the provenance of the run
(:func:`ddfv.provenance.provenance` of the run settings). NaN is stored as
``null`` so that the file is standard JSON. Records are written atomically
(temporary file + rename): a killed job leaves no half record.
"""

import json
import logging
import math
import os
import sys
import tempfile
from dataclasses import fields
from pathlib import Path

# Runs from a checkout need no install: the repository root (the folder of
# the Snakefile) goes first on sys.path when it holds the packages. Scripts
# import this module before any package of the repository.
REPOSITORY = Path(__file__).resolve().parents[2]
if (REPOSITORY / "ddfv" / "__init__.py").is_file() and str(REPOSITORY) not in sys.path:
    sys.path.insert(0, str(REPOSITORY))

from ddfv.provenance import config_hash  # noqa: E402
from ddfv.sphere import SphereRun  # noqa: E402

STATUSES = ("ok", "solver_failed", "degenerated")
# field -> type; float fields may be null (NaN)
FIELDS = {f.name: f.type for f in fields(SphereRun)}
FIELDS.update({"scheme": str, "module": str, "options": dict, "t_final": float,
               "rtol": float, "provenance": dict})


RECOMPUTE = "delete it and run snakemake again to recompute it"


class RecordError(ValueError):
    """A run record that cannot be used; the message names the file."""


def setup_logging(log_file):
    """Log to the job's log file and to stderr (shown by Snakemake)."""
    Path(log_file).parent.mkdir(parents=True, exist_ok=True)
    handlers = [logging.FileHandler(log_file, mode="w"), logging.StreamHandler(sys.stderr)]
    logging.basicConfig(level=logging.INFO, handlers=handlers, force=True,
                        format="%(asctime)s %(levelname)s %(message)s")
    return logging.getLogger("pipeline")


def _json_value(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _json_value(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_value(v) for v in value]
    return value


def write_text_atomic(path, text):
    """Write ``text`` to ``path`` through a temporary file + rename."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    umask = os.umask(0)
    os.umask(umask)
    try:
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; results are for everyone
        with os.fdopen(fd, "w") as out:
            out.write(text)
            out.flush()
            os.fsync(out.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json_atomic(path, data):
    """Write ``data`` as standard JSON (NaN as null), atomically."""
    write_text_atomic(path, json.dumps(_json_value(data), indent=2, allow_nan=False) + "\n")


def read_record(path, expected):
    """Read and check one run record.

    Parameters
    ----------
    path : str or Path
    expected : dict
        The run settings the record must come from (scheme, level, ...).

    Returns
    -------
    dict
        The record, null floats as NaN.

    Raises
    ------
    RecordError
        Unreadable or invalid JSON, a missing key, a value of the wrong type,
        an unknown status, or settings other than ``expected`` (a stale
        record: its provenance config hash differs).
    """
    record = load_record(path, FIELDS, "run record")
    for key, kind in FIELDS.items():
        value = record[key]
        if kind is float:
            ok = value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))
        elif kind is int:
            ok = isinstance(value, int) and not isinstance(value, bool)
        else:
            ok = isinstance(value, kind)
        if not ok:
            raise RecordError(f"{path}: key {key!r} should be {kind.__name__}"
                              f"{' or null' if kind is float else ''}, "
                              f"got {value!r}; {RECOMPUTE}")
        if kind is float:
            record[key] = float("nan") if value is None else float(value)
    if record["status"] not in STATUSES:
        raise RecordError(f"{path}: unknown status {record['status']!r} "
                          f"(expected one of {', '.join(STATUSES)}); {RECOMPUTE}")
    for key in ("scheme", "level"):
        if record[key] != expected[key]:
            raise RecordError(f"{path}: {key} is {record[key]!r}, expected "
                              f"{expected[key]!r}; {RECOMPUTE}")
    check_config_hash(path, record, expected)
    return record


def load_record(path, required, what):
    """Read a JSON record that must be an object with the keys ``required``.

    Raises
    ------
    RecordError
        Unreadable file, invalid JSON, not an object, or a missing key; the
        message names the file and says how to recompute it.
    """
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
    missing = [k for k in required if k not in record]
    if missing:
        raise RecordError(f"{path}: missing key(s) {missing}; {RECOMPUTE}")
    return record


def check_config_hash(path, record, expected):
    """Refuse a record whose provenance hash is not that of ``expected`` (stale)."""
    provenance = record["provenance"]
    stored = provenance.get("config_hash") if isinstance(provenance, dict) else None
    if stored != config_hash(expected):
        raise RecordError(f"{path}: config hash {stored!r} does not match the current "
                          f"settings {expected} (hash {config_hash(expected)!r}): the record "
                          f"is stale or was edited; {RECOMPUTE}")
