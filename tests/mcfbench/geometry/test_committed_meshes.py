"""The real meshes committed under mcfbench/data/meshes (mcfbench.geometry.committed_meshes):
each file has the manifest's SHA-256, reads through the project's intake as one
closed, manifold, consistently oriented surface with positive enclosed volume,
and has the counts, Euler characteristic and genus the manifest (and the README
table made from it) states."""

import hashlib

import pytest

from mcfbench.geometry import committed_meshes
from mcfbench.geometry.committed_meshes import (
    MESH_DIR,
    committed_mesh_file,
    mesh_manifest,
    read_committed_mesh,
)
from mcfbench.geometry.mesh import summarize
from mcfbench.geometry.metrics import volume

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
