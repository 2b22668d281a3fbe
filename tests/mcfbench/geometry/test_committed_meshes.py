"""The real meshes committed under mcfbench/data/meshes (mcfbench.geometry.committed_meshes):
each file has the manifest's SHA-256, reads through the project's intake as one
closed, manifold, consistently oriented surface with positive enclosed volume,
and has the counts, Euler characteristic and genus the manifest (and the README
table made from it) states. The raw corpus under mcfbench/data/raw_meshes: every
file has its manifest's SHA-256, licence and provenance, and reads through the
intake with the counts, topology, quality and thin-feature verdict stated, or is
refused by it with the defect the manifest names."""

import hashlib

import pytest

from mcfbench.geometry import committed_meshes
from mcfbench.geometry.committed_meshes import (
    MESH_DIR,
    RAW_DIR,
    committed_mesh_file,
    mesh_manifest,
    raw_manifest,
    raw_mesh_file,
    read_committed_mesh,
    read_raw_mesh,
)
from mcfbench.geometry.mesh import MeshError, summarize
from mcfbench.geometry.metrics import volume
from mcfbench.geometry.thickness import thin_features

MANIFEST = mesh_manifest()


PERMISSIVE = ("CC0 1.0", "MIT", "CC BY")
"""The licences a committed mesh may have (a mesh without a stated permissive licence is
not committed: mcfbench/data/meshes/README.md names the ones withheld)."""


def test_the_collection_is_permissively_licensed_and_mixes_kinds_and_topologies():
    kinds = {e["kind"] for e in MANIFEST.values()}
    assert all(e["licence"].startswith(PERMISSIVE) for e in MANIFEST.values())
    assert {"CAD", "modelled"} <= kinds
    assert any(e["genus"] > 0 for e in MANIFEST.values())
    assert any(e["thin_features"] for e in MANIFEST.values())
    sizes = sum((MESH_DIR / e["file"]).stat().st_size for e in MANIFEST.values())
    assert sizes < 15e6


@pytest.mark.parametrize("name", sorted(MANIFEST))
def test_committed_mesh_is_a_closed_oriented_surface_as_the_manifest_states(name):
    entry = MANIFEST[name]
    V, F = read_committed_mesh(name)       # the intake validates: manifold, oriented, no repair
    s = summarize(V, F)
    assert (s.vertices, s.faces) == (entry["vertices"], entry["faces"])
    assert s.components == 1 and s.closed
    assert s.euler_characteristic == entry["euler_characteristic"] == 2 - 2 * entry["genus"]
    assert s.genus == (entry["genus"],)
    assert volume(V, F) > 0                 # outward normals
    assert entry["vertices"] <= 15000 and entry["kind"] in ("scan", "CAD", "modelled")
    assert entry["licence"] and entry["author"] and len(entry["commit"]) == 40


def test_readme_table_lists_every_manifest_entry_with_its_counts():
    readme = (MESH_DIR / "README.md").read_text()
    for entry in MANIFEST.values():
        row = next(line for line in readme.splitlines() if line.startswith(f"| `{entry['file']}`"))
        cells = [c.strip() for c in row.split("|")[1:-1]]
        assert cells[1:6] == [entry["kind"], str(entry["vertices"]), str(entry["faces"]),
                              str(entry["euler_characteristic"]), str(entry["genus"])]


def test_corrupted_file_is_refused_by_its_sha256(tmp_path, monkeypatch):
    name = "nut"
    data = bytearray(committed_mesh_file(name).read_bytes())
    data[-1] ^= 1
    (tmp_path / MANIFEST[name]["file"]).write_bytes(bytes(data))
    (tmp_path / "manifest.json").write_text((MESH_DIR / "manifest.json").read_text())
    monkeypatch.setattr(committed_meshes, "MESH_DIR", tmp_path)
    with pytest.raises(ValueError, match="nut.*SHA-256.*corrupted"):
        committed_mesh_file(name)
    assert hashlib.sha256(bytes(data)).hexdigest() != MANIFEST[name]["sha256"]


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(ValueError, match="unknown committed mesh 'teapot'; choose one of .*spot"):
        committed_mesh_file("teapot")


# --- the raw corpus (mcfbench/data/raw_meshes): meshes as they come ---------

RAW = raw_manifest()

RAW_LICENCES = ("CC0 1.0", "MIT", "CC BY", "BSD", "Apache", "public domain")
"""The stated permissive licences a raw corpus member may have."""


def test_raw_corpus_has_thirty_public_meshes_as_they_come_of_every_kind_and_defect():
    raw = [e for e in RAW.values() if e["origin"] == "raw"]
    read = [e for e in RAW.values() if e["intake"] == "read"]
    assert len([e for e in raw if e["intake"] == "read"]) >= 30
    assert all(e["licence"].startswith(RAW_LICENCES) and e["author"] for e in RAW.values())
    assert {e["kind"] for e in raw} == {"scan", "CAD", "modelled"}
    traits = {t for e in read for t in e["traits"]}
    assert {"open boundary", "several components", "slivers", "thin features", "polygons",
            "soup"} <= traits
    assert any(e["thin_features"] for e in read) and not all(e["thin_features"] for e in read)
    assert {e["defect"] for e in RAW.values() if e["intake"] == "refused"} >= {
        "non-manifold edge", "non-manifold vertex", "inconsistent orientation",
        "duplicate triangle", "zero-area triangle"}
    assert sum((RAW_DIR / e["file"]).stat().st_size for e in RAW.values()) < 6e6
    assert not set(RAW) & set(MANIFEST)     # the corpus and the problem meshes are apart


@pytest.mark.parametrize("name", sorted(RAW))
def test_raw_mesh_matches_its_manifest_or_is_refused_with_the_named_defect(name):
    entry = RAW[name]
    path = raw_mesh_file(name)               # the SHA-256 checked
    assert entry["bytes"] == path.stat().st_size
    assert entry["licence"] and entry["repository"] and len(entry["commit"]) == 40
    assert entry["kind"] in ("scan", "CAD", "modelled") and entry["processing"]
    if entry["origin"] == "generated":
        base = MANIFEST[entry["processing"].split("'")[1]]
        assert (entry["commit"], entry["licence"]) == (base["commit"], base["licence"])
    if entry["intake"] == "refused":
        with pytest.raises(MeshError) as refused:
            read_raw_mesh(name)
        assert refused.value.kind == entry["defect"]
        return
    V, F, report = read_raw_mesh(name)
    s = summarize(V, F)
    assert (report.file_vertices, report.file_faces) == (entry["file_vertices"], entry["file_faces"])
    assert report.notes() == entry["repairs"]
    assert (s.vertices, s.faces, s.components, s.boundary_loops) == (
        entry["vertices"], entry["faces"], entry["components"], entry["boundary_loops"])
    assert sorted(set(s.genus)) == entry["genus"] and s.vertices <= 20000
    assert s.smallest_angle == pytest.approx(entry["smallest_angle"], abs=1e-4)
    assert s.area_ratio == pytest.approx(entry["area_ratio"], rel=1e-4)
    thin = thin_features(V, F)
    assert thin.mean_edge == pytest.approx(entry["mean_edge"], rel=1e-5)
    assert thin.thin_share == pytest.approx(entry["thin_share"], abs=1e-5)
    assert thin.thin is entry["thin_features"] is ("thin features" in entry["traits"])


def test_raw_readme_table_lists_every_member_with_its_counts_and_verdict():
    readme = (RAW_DIR / "README.md").read_text()
    for entry in RAW.values():
        row = next(line for line in readme.splitlines() if line.startswith(f"| `{entry['file']}`"))
        cells = [c.strip() for c in row.split("|")[1:-1]]
        assert cells[1:3] == [entry["origin"], entry["kind"]]
        if entry["intake"] == "read":
            assert cells[3:6] == [str(entry["vertices"]), str(entry["faces"]),
                                  str(entry["components"])]
            assert cells[9].startswith("yes" if entry["thin_features"] else "no")
        else:
            assert cells[10] == f"refused: {entry['defect']}"


def test_replaced_raw_file_is_refused_by_its_sha256(tmp_path, monkeypatch):
    name = "tube"
    (tmp_path / RAW[name]["file"]).write_bytes(raw_mesh_file(name).read_bytes() + b"\n")
    (tmp_path / "manifest.json").write_text((RAW_DIR / "manifest.json").read_text())
    monkeypatch.setattr(committed_meshes, "RAW_DIR", tmp_path)
    with pytest.raises(ValueError, match="raw mesh 'tube'.*SHA-256.*corrupted"):
        raw_mesh_file(name)
    with pytest.raises(ValueError, match="unknown raw mesh 'teapot'; choose one of .*tube"):
        raw_mesh_file("teapot")
