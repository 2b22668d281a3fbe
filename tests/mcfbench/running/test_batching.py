"""The run store's batches (mcfbench.running.batching)."""

import pytest

from mcfbench.running.batch import spec_of
from mcfbench.running.batching import BATCH_SECONDS, batches, pack

SOLVER = {"method": "bicgstab", "rtol": 1e-9, "maxiter": 1000}


def sphere(scheme, level):
    return spec_of(scheme, "sphere", level, solver=SOLVER)


def test_a_run_two_studies_ask_for_is_in_exactly_one_batch():
    requests = {"convergence": [sphere(s, k) for s in ("ddfv", "cotan") for k in (1, 2)],
                "matrix": [sphere(s, k) for s in ("cotan", "bgn") for k in (1, 2)]}
    found = batches(requests, cost=lambda spec: 1.0)
    specs = [s for b in found for s in b.specs]
    assert len(specs) == len(set(specs)) == 6
    by_name = {b.name: b for b in found}
    assert set(by_name) == {"sphere_convergence_batch1", "sphere_convergence-matrix_batch1",
                            "sphere_matrix_batch1"}
    assert by_name["sphere_convergence-matrix_batch1"].specs == (sphere("cotan", 1),
                                                                 sphere("cotan", 2))
    # the batches of a study hold only runs it asked for
    assert all("matrix" in b.studies for b in found if sphere("bgn", 1) in b.specs)


def test_heavy_series_alone_cheap_ones_packed():
    specs = [sphere(s, 1) for s in ("ddfv", "cotan", "bgn", "mdr")]
    cost = {specs[0]: 2 * BATCH_SECONDS, specs[1]: 1.0, specs[2]: 1.0, specs[3]: 1.0}
    found = batches({"matrix": specs}, cost=cost.get)
    assert [b.specs for b in found] == [(specs[0],), tuple(specs[1:])]
    assert [b.seconds for b in found] == [2 * BATCH_SECONDS, 3.0]


def test_pack_closes_a_group_at_the_budget():
    assert pack({"a": 30, "b": 30, "c": 70, "d": 10}, 60) == [["a", "b"], ["c"], ["d"]]


def test_spec_seconds_scale_the_cost_model_by_the_kind_of_scheme(monkeypatch):
    """spec_seconds: RUN_SECONDS a run and the model's steps times the measured factor
    of the scheme's kind (MATRIX_FACTORS: BGN's series take 7.1 x its model, the
    redistributing vertex schemes 0.14 x); a matrix's heavy series alone."""
    from mcfbench.running import batching

    specs = {s: [spec_of(s, "catenoid", k, solver=SOLVER) for k in (1, 2, 3)]
             for s in ("bgn", "cotan-redistribute")}
    calibrated = {s: sum(map(batching.spec_seconds, v)) for s, v in specs.items()}
    monkeypatch.setattr(batching, "MATRIX_FACTORS", {})
    model = {s: sum(map(batching.spec_seconds, v)) for s, v in specs.items()}
    runs = 3 * batching.RUN_SECONDS
    assert (calibrated["bgn"] - runs) / (model["bgn"] - runs) == pytest.approx(7.1)
    assert (calibrated["cotan-redistribute"] - runs) / \
        (model["cotan-redistribute"] - runs) == pytest.approx(0.14)
    monkeypatch.undo()
    # catenoid levels 1-3 of BGN: its kind's factor on the model's 13 s: alone
    found = batches({"matrix": [*specs["bgn"], *specs["cotan-redistribute"],
                                sphere("cotan", 1)]})
    assert [b.specs for b in found if b.problem == "catenoid"][0] == tuple(specs["bgn"])
    assert calibrated["bgn"] >= BATCH_SECONDS


def test_mesh_files_are_packed_by_their_size_a_large_one_split(tmp_path):
    """A user's mesh file counts MESH_FILE_SECONDS a megabyte: the runs on small files
    share a batch, a large file's runs (one series per scheme) fill several, the
    costliest batches first by their estimate (runs.smk's priority)."""
    from mcfbench.running import batching
    from mcfbench.running.batch import mesh_spec

    schemes = [f"s{k}" for k in range(20)]
    files = {}
    for name, megabytes in (("tiny1", 0.001), ("tiny2", 0.002), ("large", 1.0)):
        files[name] = tmp_path / f"{name}.ply"
        files[name].write_bytes(b"x" * int(megabytes * 1e6))
    specs = [mesh_spec(s, str(path), "0" * 64, tau_edge=0.1, steps=40, solver=SOLVER,
                       frames=2) for path in files.values() for s in schemes]
    per_run = batching.RUN_SECONDS + batching.MESH_FILE_SECONDS
    assert batching.spec_seconds(specs[-1]) == pytest.approx(per_run)
    assert batching.spec_seconds(specs[0]) == pytest.approx(
        batching.RUN_SECONDS + 0.001 * batching.MESH_FILE_SECONDS)
    found = batches({"survival": specs})
    assert sorted(s.key for b in found for s in b.specs) == sorted(s.key for s in specs)
    holding = {name: [b for b in found if str(path) in {s.mesh_file for s in b.specs}]
               for name, path in files.items()}
    assert len(holding["tiny1"]) == 1 and holding["tiny1"] == holding["tiny2"]
    assert len(holding["large"]) >= 20 * per_run // BATCH_SECONDS >= 2
    assert all(b.seconds < BATCH_SECONDS + per_run for b in found)
    missing = mesh_spec("s0", str(tmp_path / "gone.ply"), "0" * 64, tau_edge=0.1, steps=40,
                        solver=SOLVER, frames=2)
    assert batching.spec_seconds(missing) == BATCH_SECONDS
