"""Reading mesh files: errors, intake repairs and numbering (mcfbench.geometry.mesh_files)."""

import numpy as np
import pytest

from mcfbench.geometry.mesh import summarize
from mcfbench.geometry.mesh_files import read_mesh

TET_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def write_obj(path, V, F, extra=""):
    lines = [f"v {float(x)!r} {float(y)!r} {float(z)!r}" for x, y, z in V] + [
        "f " + " ".join(str(i + 1) for i in f) for f in F]
    path.write_text("\n".join(lines) + "\n" + extra)
    return path


def write_off(path, V, faces):
    lines = ["OFF", f"{len(V)} {len(faces)} 0"] + [" ".join(map(str, v)) for v in V] + [
        f"{len(f)} " + " ".join(map(str, f)) for f in faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def write_stl_soup(path, V, F):
    lines = ["solid soup"]
    for f in F:
        lines += ["facet normal 0 0 0", "outer loop"]
        lines += [f"vertex {x} {y} {z}" for x, y, z in V[f]]
        lines += ["endloop", "endfacet"]
    path.write_text("\n".join(lines + ["endsolid soup"]) + "\n")
    return path


def test_obj(tmp_path):
    V, F, report = read_mesh(write_obj(tmp_path / "tet.obj", TET_V, TET_F))
    assert np.array_equal(V, TET_V) and np.array_equal(F, TET_F)
    assert V.dtype == np.float64 and F.dtype == np.int64
    assert report.notes() == []
    assert (report.file_vertices, report.file_faces, report.triangles) == (4, 4, 4)
    assert report.kept.tolist() == [0, 1, 2, 3]


def test_off(tmp_path):
    V, F, report = read_mesh(write_off(tmp_path / "tet.off", TET_V, TET_F))
    assert np.array_equal(V, TET_V) and np.array_equal(F, TET_F)
    assert report.notes() == []


def test_stl_soup_is_merged_into_a_closed_surface(tmp_path):
    V, F, report = read_mesh(write_stl_soup(tmp_path / "tet.stl", TET_V, TET_F))
    assert (len(V), len(F)) == (4, 4)
    assert report.file_vertices == 12 and report.merged == 8
    assert report.notes() == ["merged 8 coincident vertices"]
    # file vertices 0-2 are corners 0, 2, 1 of TET_F[0], vertex 5 the first copy of corner 3
    assert report.kept.tolist() == [0, 1, 2, 5]
    assert report.new_index.tolist() == [0, 1, 2, 0, 2, 3, 0, 3, 1, 2, 1, 3]
    assert np.array_equal(V, TET_V[[0, 2, 1, 3]])
    s = summarize(V, F)
    assert (s.boundary_loops, s.components, s.genus) == (0, 1, (0,))


def test_unreferenced_vertices_are_dropped_and_mapped(tmp_path):
    file_V = np.vstack([[[7, 7, 7]], TET_V[:2], [[8, 8, 8]], TET_V[2:]])  # 0 and 3 unused
    file_F = np.array([[1, 4, 2], [1, 2, 5], [1, 5, 4], [2, 4, 5]])
    V, F, report = read_mesh(write_obj(tmp_path / "extra.obj", file_V, file_F))
    assert report.notes() == ["dropped 2 unreferenced vertices"]
    assert report.kept.tolist() == [1, 2, 4, 5]
    assert report.new_index.tolist() == [-1, 0, 1, -1, 2, 3]
    assert np.array_equal(V, TET_V) and np.array_equal(F, TET_F)
    assert np.array_equal(report.kept[F], file_F)           # faces in the file's numbering
    back = report.to_file_order(V + 1.0)
    assert np.array_equal(back[[1, 2, 4, 5]], TET_V + 1.0) and np.isnan(back[[0, 3]]).all()


def test_off_quads_are_split_into_triangles(tmp_path):
    cube = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    V, F, report = read_mesh(write_off(tmp_path / "cube.off", cube, quads))
    assert report.notes() == ["split 6 polygons into 12 triangles (fan from the first corner)"]
    assert (report.file_faces, report.polygons, report.triangles) == (6, 6, 12)
    assert report.face_of.tolist() == [0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5]
    assert F[:2].tolist() == [[0, 2, 3], [0, 3, 1]]
    s = summarize(V, F)
    assert (s.faces, s.edges, s.genus, s.boundary_loops) == (12, 18, (0,), 0)


def test_nan_coordinate_names_the_vertex(tmp_path):
    path = tmp_path / "nan.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv nan 0 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match=r"nan.obj: NaN, inf or unreadable coordinates at "
                       r"vertex 2 \(0-based; line 3: 'v nan 0 0'\)"):
        read_mesh(path)
    write_off(tmp_path / "nan.off", [[0, 0, 0], ["inf", 0, 0], [0, 1, 0]], [[0, 1, 2]])
    with pytest.raises(ValueError, match=r"vertex 1 \(0-based; line 4: 'inf 0 0'\)"):
        read_mesh(tmp_path / "nan.off")


def test_invalid_surface_is_named_in_the_files_numbering(tmp_path):
    # two triangles touching at one point; file vertex 0 is unused
    V = np.array([[9, 9, 9], [0, 0, 0], [1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]], float)
    path = write_obj(tmp_path / "bowtie.obj", V, [[1, 2, 3], [1, 4, 5]])
    with pytest.raises(ValueError, match=r"bowtie.obj: non-manifold vertex\(es\) \[1\]"):
        read_mesh(path)


def test_empty_file(tmp_path):
    (tmp_path / "empty.obj").write_text("")
    with pytest.raises(ValueError, match="empty.obj: the file is empty"):
        read_mesh(tmp_path / "empty.obj")


def test_unknown_extension(tmp_path):
    write_obj(tmp_path / "tet.txt", TET_V, TET_F)
    with pytest.raises(ValueError, match=r"tet.txt: unsupported mesh format '.txt'; "
                       r"supported: .obj .off .ply .stl"):
        read_mesh(tmp_path / "tet.txt")


def test_directory(tmp_path):
    (tmp_path / "mesh.obj").mkdir()
    with pytest.raises(ValueError, match="mesh.obj is a directory, not a mesh file"):
        read_mesh(tmp_path / "mesh.obj")


def test_nonexistent_path(tmp_path):
    with pytest.raises(FileNotFoundError, match="mesh file not found: .*missing.off"):
        read_mesh(tmp_path / "missing.off")


def test_unreadable_content_quotes_libigl(tmp_path):
    (tmp_path / "junk.off").write_text("this is not a mesh\n")
    with pytest.raises(ValueError, match=r"junk.off: libigl could not read this OFF file: "
                       r"Error: readOFF\(\) first line should be OFF"):
        read_mesh(tmp_path / "junk.off")


def test_no_faces(tmp_path):
    (tmp_path / "points.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    with pytest.raises(ValueError, match="points.obj: the file has 3 vertices but no faces"):
        read_mesh(tmp_path / "points.obj")


def test_face_with_two_corners(tmp_path):
    path = write_obj(tmp_path / "edge.obj", TET_V, TET_F, extra="f 1 2\n")
    with pytest.raises(ValueError, match=r"face\(s\) \[4\] have fewer than 3 corners, e.g. "
                       r"face 4 \(line 9\) has 2"):
        read_mesh(path)


def test_a_crash_of_the_reader_becomes_a_value_error(tmp_path):
    # libigl's PLY reader aborts the process on faces of different sizes
    path = tmp_path / "mixed.ply"
    path.write_text("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\n"
                    "property float y\nproperty float z\nelement face 2\n"
                    "property list uchar int vertex_indices\nend_header\n"
                    "0 0 0\n1 0 0\n1 1 0\n0 1 0\n0.5 2 0\n4 0 1 2 3\n3 3 2 4\n")
    with pytest.raises(ValueError, match=r"mixed.ply: libigl could not read this PLY file "
                       r"\(the reader crashed with signal 6\).*variable length lists"):
        read_mesh(path)
