"""The run store (mcfbench.storage.run_store): a run is its spec, one key, one path."""

import json

import pytest

from mcfbench.storage import run_store
from mcfbench.storage.records import RecordError, checksum, write_record
from mcfbench.storage.run_store import RunSpec

SOLVER = {"method": "bicgstab", "rtol": 1e-9, "maxiter": 1000}


def sphere(**kwargs):
    return RunSpec.make(**{"scheme": "cotan", "problem": "sphere", "level": 2,
                           "solver": SOLVER, "tau": 0.01, "t_final": 0.08, **kwargs})


def test_equal_runs_asked_in_other_words_are_one_spec_and_one_key():
    a = sphere()
    b = RunSpec.make("cotan", "sphere", "2", solver={"rtol": "1e-9", "maxiter": 1000.0,
                                                   "method": "bicgstab"},
                     tau=0.01, t_final=8e-2, threads=1.0)
    assert a == b and hash(a) == hash(b) and a.key == b.key
    assert len(a.key) == 16 and int(a.key, 16) >= 0
    assert RunSpec.from_dict(json.loads(json.dumps(a.to_dict()))) == a


@pytest.mark.parametrize("change", [{"level": 3}, {"tau": 0.005}, {"t_final": 0.04},
                                    {"threads": 2}, {"frames": 20}, {"scheme": "bgn"},
                                    {"solver": {**SOLVER, "maxiter": 999}},
                                    {"solver": {**SOLVER, "rtol": 1e-8}}])
def test_every_setting_that_changes_the_numbers_changes_the_key(change):
    assert sphere(**change).key != sphere().key


def test_a_path_per_key_in_one_store():
    spec = sphere()
    assert run_store.record_path(spec) == f"results/runs/sphere/cotan/level2/{spec.key}.json"
    assert run_store.frames_path(spec) == f"results/runs/sphere/cotan/level2/{spec.key}.npz"


def test_a_spec_has_one_time_rule_and_a_mesh_file_its_digest():
    with pytest.raises(ValueError, match="tau and t_final"):
        RunSpec.make("cotan", "sphere", 1, solver=SOLVER, tau=0.01)
    with pytest.raises(ValueError, match="tau and t_final"):
        RunSpec.make("cotan", "real_bob", 1, solver=SOLVER, tau=0.01, t_final=0.1,
                     tau_edge=0.1, steps=40)
    with pytest.raises(ValueError, match="SHA-256"):
        RunSpec.make("cotan", "gallery", 1, solver=SOLVER, tau_edge=0.1, steps=40,
                     mesh_file="a.obj")
    with pytest.raises(ValueError, match="keys method"):
        RunSpec.make("cotan", "sphere", 1, solver={"method": "bicgstab"}, tau=0.01,
                     t_final=0.08)
    mesh = RunSpec.make("cotan", "gallery", 1, solver=SOLVER, tau_edge=0.1, steps=40,
                        mesh_file="a.obj", mesh_sha256="ab")
    assert mesh.key != RunSpec.make("cotan", "gallery", 1, solver=SOLVER, tau_edge=0.1,
                                    steps=40, mesh_file="a.obj", mesh_sha256="cd").key


def _result(spec):
    return {"scheme": spec.scheme, "problem": spec.problem, "level": spec.level, "nV": 1,
            "nF": 1, "nT": 0, "h": 0.1, "tau": spec.tau, "N": 8, "steps_done": 8,
            "status": "ok", "message": "", "t_failed": None, "t_end": 0.08, "steady": False,
            "iterations": 3, "solver": "bicgstab", "integrator": "euler",
            "cpu_seconds": 0.1, "wall_seconds": 0.1, "t_min_barycentric": None,
            "min_angle": 0.5, "max_aspect": 2.0, "max_flipped": 0.0, "series": {}}


def test_stored_and_read_only_with_the_same_key_and_code_digest(tmp_path):
    spec, root = sphere(), str(tmp_path)
    assert not run_store.stored(spec, "c0de", root)
    path = run_store.record_path(spec, root)
    write_record(path, _result(spec), run_store.store_settings(spec, "c0de"))
    assert not run_store.stored(spec, "c0de", root)          # no frames yet
    (tmp_path / run_store.frames_path(spec, "").lstrip("/")).write_bytes(b"")
    assert run_store.stored(spec, "c0de", root)
    assert not run_store.stored(spec, "other", root)
    assert run_store.read_run(spec, "c0de", root)["iterations"] == 3
    with pytest.raises(RecordError, match=r"level2/\w{16}\.json: its settings are not the "
                                          r"current ones .* the record is stale"):
        run_store.read_run(spec, "other", root)


def test_read_runs_names_every_bad_or_stale_record(tmp_path):
    root = str(tmp_path)
    good, edited, stale, missing = (sphere(level=k) for k in (1, 2, 3, 4))
    for spec in (good, edited, stale):
        write_record(run_store.record_path(spec, root), _result(spec),
                     run_store.store_settings(spec, "c0de"))
    record = json.loads(open(run_store.record_path(edited, root)).read())
    record["iterations"] = 9
    open(run_store.record_path(edited, root), "w").write(json.dumps(record))
    record = json.loads(open(run_store.record_path(stale, root)).read())
    record["settings"]["code"] = "old"                 # computed by other code
    record["provenance"]["config_hash"] = "0123456789abcdef"
    record["checksum"] = checksum(record)
    open(run_store.record_path(stale, root), "w").write(json.dumps(record))
    with pytest.raises(RecordError) as err:
        run_store.read_runs({s: "c0de" for s in (good, edited, stale, missing)}, root=root)
    text = str(err.value)
    assert "3 invalid run record(s)" in text
    assert f"level2/{edited.key}.json: checksum does not match" in text
    assert f"level3/{stale.key}.json: its settings are not the current ones" in text
    assert f"level4/{missing.key}.json: cannot read record" in text
    assert list(run_store.read_runs({good: "c0de"}, root=root)) == [good]
