"""Run records (mcfbench/storage/records.py): schema, checksum, stale settings, atomic write."""

import json
import math

import pytest

from mcfbench.running.run import run
from mcfbench.storage.records import RecordError, read_record, read_records, write_record

SETTINGS = {"scheme": "cotan", "problem": "sphere", "level": 1}


@pytest.fixture(scope="module")
def result():
    return run("cotan", "sphere", 1)[0]


def test_record_round_trip(tmp_path, result):
    path = tmp_path / "level1.json"
    write_record(path, result, SETTINGS)
    record = read_record(path, SETTINGS)
    assert record["l2_error"] == result.metrics["l2_error"]
    assert record["iterations"] == result.iterations and record["status"] == "ok"
    assert math.isnan(record["t_failed"]) and math.isnan(record["t_min_barycentric"])
    assert record["provenance"]["config"] == SETTINGS
    # the peak memory of the process that wrote it (ru_maxrss), next to the run's times
    assert record["wall_seconds"] > 0 and 10 < record["peak_rss_mb"] < 10_000
    assert json.loads(path.read_text())["t_failed"] is None       # standard JSON


def test_edited_record_is_refused(tmp_path, result):
    path = tmp_path / "level1.json"
    write_record(path, result, SETTINGS)
    record = json.loads(path.read_text())
    record["l2_error"], record["iterations"] = 0.5, 1          # valid, but not computed
    path.write_text(json.dumps(record))
    with pytest.raises(RecordError, match="checksum does not match"):
        read_record(path, SETTINGS)


def test_stale_record_is_refused(tmp_path, result):
    path = tmp_path / "level1.json"
    write_record(path, result, SETTINGS)
    with pytest.raises(RecordError, match="stale"):
        read_record(path, {**SETTINGS, "level": 2})


@pytest.mark.parametrize("text, message", [
    ("{", "not valid JSON"),
    ("[1, 2]", "expected a JSON object"),
    ('{"status": "ok"}', "missing key"),
])
def test_damaged_records_are_named(tmp_path, text, message):
    path = tmp_path / "bad.json"
    path.write_text(text)
    with pytest.raises(RecordError, match=message) as err:
        read_record(path)
    assert str(path) in str(err.value)


def test_read_records_names_every_bad_record_not_only_the_first(tmp_path, result):
    good, stale, damaged = (tmp_path / f"{name}.json" for name in ("good", "stale", "damaged"))
    for path in (good, stale):
        write_record(path, result, SETTINGS)
    damaged.write_text("{")
    expected = {good: SETTINGS, stale: {**SETTINGS, "level": 2}, damaged: SETTINGS}
    with pytest.raises(RecordError, match="2 invalid run record") as err:
        read_records(expected)
    assert str(stale) in str(err.value) and str(damaged) in str(err.value)
    assert str(good) not in str(err.value)
    assert list(read_records({good: SETTINGS})) == [good]


def test_a_record_written_before_timing_repeats_existed_reads_as_timed_once(tmp_path, result):
    from mcfbench.storage.records import checksum

    path = tmp_path / "level1.json"
    record = write_record(path, result, SETTINGS)
    assert record["timing_repeats"] == result.timing_repeats > 1    # a 1-ms run, repeated
    del record["timing_repeats"]
    record["checksum"] = checksum(record)
    path.write_text(json.dumps(record))
    assert read_record(path, SETTINGS)["timing_repeats"] == 1
    record["timing_repeats"] = "many"
    record["checksum"] = checksum(record)
    path.write_text(json.dumps(record))
    with pytest.raises(RecordError, match="'timing_repeats' should be int"):
        read_record(path, SETTINGS)


def test_a_record_carries_its_format_version_and_a_newer_one_is_refused(tmp_path, result):
    """format_version 1 written; a record without it (written before) reads as version 0
    with everything else as it was; a newer version is refused, naming the file."""
    from mcfbench.storage.records import FORMAT_VERSION, checksum

    path = tmp_path / "level1.json"
    record = write_record(path, result, SETTINGS)
    assert record["format_version"] == FORMAT_VERSION == 1
    assert read_record(path, SETTINGS)["format_version"] == 1
    del record["format_version"]
    record["checksum"] = checksum(record)
    path.write_text(json.dumps(record))
    old = read_record(path, SETTINGS)
    assert old["format_version"] == 0 and old["l2_error"] == result.metrics["l2_error"]
    record["format_version"] = 2
    record["checksum"] = checksum(record)
    path.write_text(json.dumps(record))
    with pytest.raises(RecordError, match=r"level1\.json: a run record of format_version 2, "
                                          r"written by a newer mcfbench"):
        read_record(path, SETTINGS)
