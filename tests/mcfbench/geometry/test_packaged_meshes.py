"""The real meshes shipped inside pinned packages (mcfbench.geometry.packaged_meshes):
each is installed, has the recorded SHA-256, reads through read_mesh with the
documented counts and topology, and the default gallery lists it."""

import pytest

from mcfbench.geometry.mesh import summarize
from mcfbench.geometry.packaged_meshes import (
    PACKAGED_MESHES,
    gifti_surface,
    read_packaged_mesh,
)
from mcfbench.studies.gallery import job as gallery_job
from mcfbench.studies.gallery import plan as gallery_plan


@pytest.mark.parametrize("name", sorted(PACKAGED_MESHES))
def test_packaged_mesh_reads_with_the_documented_counts(name):
    mesh = PACKAGED_MESHES[name]
    V, F, report = read_packaged_mesh(name)
    s = summarize(V, F)
    assert (s.vertices, s.faces) == (mesh.vertices, mesh.triangles)
    assert s.components == mesh.components
    assert s.boundary_loops == mesh.boundary_loops
    assert set(s.genus) == {mesh.genus}
    assert report.notes() == []  # nothing to repair: the files are clean surfaces
    assert mesh.vertices <= 11000 and mesh.kind in ("scan", "CAD", "modelled")


def test_packaged_meshes_mix_scans_and_cad():
    kinds = {m.kind for m in PACKAGED_MESHES.values()}
    assert {"scan", "CAD"} <= kinds and 3 <= len(PACKAGED_MESHES) <= 5


def test_default_gallery_runs_the_generated_and_the_packaged_meshes():
    plan = gallery_plan.plan()
    for name in PACKAGED_MESHES:
        assert plan["meshes"][f"{name}.obj"] == f"results/gallery/meshes/{name}.obj"
        assert plan["generated"][f"{name}.obj"] == ("packaged", name, 0)
    own = [k for k, (kind, _, _) in plan["generated"].items() if kind != "packaged"]
    assert own  # the suite's own meshes stay
    assert gallery_plan.plan({}, meshes=None)["meshes"] == plan["meshes"]


def test_packaged_mesh_is_written_as_obj_the_gallery_reads(tmp_path):
    from mcfbench.geometry.mesh_files import read_mesh

    path = tmp_path / "nut.obj"
    gallery_job.write_generated_mesh(("packaged", "nut", 0), path)
    V, F, _ = read_mesh(path)
    assert (len(V), len(F)) == (PACKAGED_MESHES["nut"].vertices, PACKAGED_MESHES["nut"].triangles)


def test_a_changed_package_file_is_refused(monkeypatch, tmp_path):
    from dataclasses import replace

    from mcfbench.geometry import packaged_meshes

    wrong = replace(PACKAGED_MESHES["nut"], sha256="0" * 64)
    monkeypatch.setitem(packaged_meshes.PACKAGED_MESHES, "nut", wrong)
    with pytest.raises(ValueError, match="SHA-256"):
        read_packaged_mesh("nut")
    missing = replace(wrong, package="no-such-package-mcfbench")
    monkeypatch.setitem(packaged_meshes.PACKAGED_MESHES, "nut", missing)
    with pytest.raises(FileNotFoundError, match="not installed"):
        read_packaged_mesh("nut")


def test_gifti_ascii_surface(tmp_path):
    path = tmp_path / "tet.gii"
    arrays = [("NIFTI_INTENT_POINTSET", "NIFTI_TYPE_FLOAT32", 4, "0 0 0 1 0 0 0 1 0 0 0 1"),
              ("NIFTI_INTENT_TRIANGLE", "NIFTI_TYPE_INT32", 4, "0 2 1 0 1 3 0 3 2 1 2 3")]
    body = "".join(f'<DataArray Intent="{i}" DataType="{t}" ArrayIndexingOrder="RowMajorOrder" '
                   f'Dimensionality="2" Dim0="{n}" Dim1="3" Encoding="ASCII" '
                   f'Endian="LittleEndian"><Data>{d}</Data></DataArray>'
                   for i, t, n, d in arrays)
    path.write_text(f'<?xml version="1.0"?><GIFTI Version="1.0">{body}</GIFTI>')
    V, F = gifti_surface(path)
    assert V.shape == (4, 3) and F.tolist()[1] == [0, 1, 3]


def test_results_readme_documents_each_packaged_mesh():
    from pathlib import Path

    text = (Path(__file__).resolve().parents[3] / "results" / "README.md").read_text()
    for mesh in PACKAGED_MESHES.values():
        row = next((line for line in text.splitlines() if line.startswith(f"| `{mesh.name}` |")),
                   None)
        assert row is not None, f"results/README.md has no row for {mesh.name}"
        cells = [c.strip() for c in row.split("|")]
        assert f"`{mesh.package}=={mesh.version}`" in row and f"`{mesh.path}`" in row
        assert str(mesh.vertices) in cells and str(mesh.triangles) in cells
