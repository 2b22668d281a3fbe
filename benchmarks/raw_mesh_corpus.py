"""Build and describe the raw-mesh corpus ``mcfbench/data/raw_meshes/`` (issue #44, item 4).

The corpus: public meshes *as they come* (scans, CAD parts, modelled
characters; slivers, creases, thin features, open boundaries, several
components, files the intake refuses) with their source and licence, plus
generated defects of the committed problem meshes (``mcfbench/data/meshes``).
No scheme is run here: the survival study runs them.

    python benchmarks/raw_mesh_corpus.py --import-from /path/to/mirrors   # copy the sources
    python benchmarks/raw_mesh_corpus.py                                  # generate, describe

``--import-from ROOT`` copies each source file from a git directory
``ROOT/<owner>+<name>/repo`` at the recorded commit (``git show
COMMIT:PATH``; PyVista's from the installed pinned wheel): a file under
``KEEP_BYTES`` is committed byte for byte, a larger one is converted to
binary PLY holding the vertices and triangles exactly as libigl reads the
source (float64; nothing merged, dropped or reoriented: STL soups stay
soups; polygons are split by libigl's fan, as the intake would), which the
manifest records as its processing. Without the option the committed raw
files are kept. Then the generated variants are remade
(:data:`GENERATED`, deterministic) and every entry's measured fields
(SHA-256, counts, the intake's outcome, topology, quality, the thin-feature
criterion of :mod:`mcfbench.geometry.thickness`) are written to
``manifest.json`` and the README's table (between its markers).
"""

import argparse
import hashlib
import importlib.metadata
import json
import subprocess
import tempfile
from pathlib import Path

import igl
import numpy as np

from mcfbench.geometry.committed_meshes import RAW_DIR, read_committed_mesh
from mcfbench.geometry.mesh import MeshError, summarize
from mcfbench.geometry.mesh_files import read_mesh
from mcfbench.geometry.metrics import volume
from mcfbench.geometry.thickness import THICKNESS_FACTOR, THIN_SHARE, thin_features
from mcfbench.storage.atomic import write_text

KEEP_BYTES = 150_000
"""Source files up to this size are committed unchanged; larger ones as binary PLY."""

SLIVER_DEGREES = 5.0
"""A mesh 'has slivers' when its smallest angle is below this."""

LAGRANGE = ("adobe/lagrange-test-data", "093892ef8ffea98350a181af48e119c7dd3e692e")
GEOMETRY_CENTRAL = ("nmwsharp/geometry-central", "56152a8afc42405ad071aaaf5a2876429ed1f7bd")
GPJS = ("GeometryCollective/geometry-processing-js", "c7ea47ae808979a5361e3fcd61bf921a194bf897")
TRIMESH = ("mikedh/trimesh", "a513c0e2cfa6dfbd3121a6dfd8ceb002b9ef55d8")
PYVISTA = ("pyvista/pyvista (file of the pinned wheel pyvista==0.49.1)",
           "be29daa26ebf56e82005024bd13362c391f70e68")

CC0_TABLE = "CC0 1.0 (stated in the repository's README table)"
MIT_TABLE = "MIT (stated in the repository's README table)"
MIT_GC = "MIT (the repository's licence; no other terms for the file)"
MIT_GPJS = "MIT (the repository's licence, README 'License: MIT'; no other terms for the file)"
MIT_TRIMESH = ("MIT (the repository's licence, LICENSE.md; the file is one of trimesh's own test "
               "models and states no other terms)")
MIT_PYVISTA = "MIT (PyVista); Greg Turk's PLY samples state no licence of their own"

HOMEMADE = "Adobe Lagrange test data (homemade)"
POLYGON_LAPLACIAN = ("Bunge, Herholz, Kazhdan, Botsch, 'Polygon Laplacian Made Simple' "
                     "(mbotsch/polygon-laplacian), via Adobe Lagrange test data")

SOURCES = {
    # name: (source, path, author / origin, licence, kind)
    "blub_open": (LAGRANGE, "open/core/blub_open.obj",
                  "Adobe Lagrange test data, derived from Keenan Crane's Blub (holes cut)",
                  CC0_TABLE, "modelled"),
    "blub_thickened": (LAGRANGE, "open/core/blub_thickened.obj",
                       "Adobe Lagrange test data, derived from Keenan Crane's Blub (open Blub "
                       "thickened into a shell)", CC0_TABLE, "modelled"),
    "cube_soup": (LAGRANGE, "open/core/cube_soup.obj", HOMEMADE, CC0_TABLE, "CAD"),
    "disk_fan": (LAGRANGE, "open/core/disk.obj", HOMEMADE, CC0_TABLE, "CAD"),
    "drop": (LAGRANGE, "open/core/drop_tri.obj", HOMEMADE, CC0_TABLE, "modelled"),
    "grid_holes": (LAGRANGE, "open/core/grid_holes.obj", HOMEMADE, CC0_TABLE, "CAD"),
    "narrow_triangles": (LAGRANGE, "open/core/narrow_triangles.obj", HOMEMADE, CC0_TABLE, "CAD"),
    "plate_crash": (LAGRANGE, "open/core/plate_crash.obj", HOMEMADE, CC0_TABLE, "CAD"),
    "hexa_sphere": (LAGRANGE, "open/core/poly/hexaSphere.obj", POLYGON_LAPLACIAN, MIT_TABLE,
                    "modelled"),
    "mixed_faring": (LAGRANGE, "open/core/poly/mixedFaring.obj", POLYGON_LAPLACIAN, MIT_TABLE,
                     "modelled"),
    "l_plane": (LAGRANGE, "open/core/poly/L-plane.obj", POLYGON_LAPLACIAN, MIT_TABLE, "CAD"),
    "tetris": (LAGRANGE, "open/core/poly/tetris.obj", POLYGON_LAPLACIAN, MIT_TABLE, "CAD"),
    "prout": (LAGRANGE, "open/core/prout.obj", HOMEMADE, CC0_TABLE, "modelled"),
    "cubes_3": (LAGRANGE, "open/core/simple/cubes-3.obj", HOMEMADE, CC0_TABLE, "CAD"),
    "table_top": (LAGRANGE, "open/core/table_top.obj", HOMEMADE, CC0_TABLE, "CAD"),
    "moebius_strip": (LAGRANGE, "open/core/topology/moebius-160-10.ply", HOMEMADE, CC0_TABLE,
                      "modelled"),
    "nonmanifold_edge": (LAGRANGE, "open/core/topology/nonmanifold_edge.obj", HOMEMADE,
                         CC0_TABLE, "CAD"),
    "torus3_in": (LAGRANGE, "open/core/torus3_in.obj", HOMEMADE, CC0_TABLE, "modelled"),
    "torus3_out": (LAGRANGE, "open/core/torus3_out.obj", HOMEMADE, CC0_TABLE, "modelled"),
    "avocado": (LAGRANGE, "open/io/avocado/avocado.obj",
                "Khronos glTF-Sample-Models 'Avocado', converted to OBJ by Adobe Lagrange",
                CC0_TABLE, "modelled"),
    "cube_esharp": (LAGRANGE, "open/subdivision/cube_esharp.obj",
                    "Adobe Lagrange test data, derived from the McGuire archive's cube",
                    CC0_TABLE, "CAD"),
    "cube_fholes": (LAGRANGE, "open/subdivision/cube_fholes.obj",
                    "Adobe Lagrange test data, derived from the McGuire archive's cube",
                    CC0_TABLE, "CAD"),
    "cat_head": (GEOMETRY_CENTRAL, "test/assets/cat_head.obj", "geometry-central test assets",
                 MIT_GC, "modelled"),
    "fan3": (GEOMETRY_CENTRAL, "test/assets/fan3.obj", "geometry-central test assets", MIT_GC,
             "CAD"),
    "fox": (GEOMETRY_CENTRAL, "test/assets/fox.ply", "geometry-central test assets (low-poly fox)",
            MIT_GC, "modelled"),
    "hourglass_ico": (GEOMETRY_CENTRAL, "test/assets/hourglass_ico.obj",
                      "geometry-central test assets (two icospheres touching at a vertex)",
                      MIT_GC, "modelled"),
    "lego": (GEOMETRY_CENTRAL, "test/assets/lego.ply",
             "geometry-central test assets (a brick's surface, open at its base)", MIT_GC, "CAD"),
    "platonic_shelf": (GEOMETRY_CENTRAL, "test/assets/platonic_shelf.obj",
                       "geometry-central test assets (five Platonic solids)", MIT_GC, "modelled"),
    "triple_vierbein": (GEOMETRY_CENTRAL, "test/assets/triple_vierbein.obj",
                        "geometry-central test assets", MIT_GC, "modelled"),
    "cowhead": (GPJS, "input/cowhead.obj", "geometry-processing-js input meshes", MIT_GPJS,
                "modelled"),
    "face": (GPJS, "input/face.obj",
             "geometry-processing-js input meshes (a face, open at the neck; its original "
             "source is not named there)", MIT_GPJS, "scan"),
    "small_disk": (GPJS, "input/small_disk.obj", "geometry-processing-js input meshes", MIT_GPJS,
                   "CAD"),
    "tray_bottom": (TRIMESH, "models/1002_tray_bottom.STL", "trimesh test models", MIT_TRIMESH,
                    "CAD"),
    "busted": (TRIMESH, "models/busted.STL", "trimesh test models", MIT_TRIMESH, "CAD"),
    "cylinder_stl": (TRIMESH, "models/cylinder.stl", "trimesh test models", MIT_TRIMESH, "CAD"),
    "featuretype": (TRIMESH, "models/featuretype.STL", "trimesh test models", MIT_TRIMESH, "CAD"),
    "fixed_top": (TRIMESH, "models/fixed_top.ply", "trimesh test models", MIT_TRIMESH, "CAD"),
    "idler_riser": (TRIMESH, "models/idler_riser.STL", "trimesh test models", MIT_TRIMESH, "CAD"),
    "plate_holes": (TRIMESH, "models/plate_holes.STL", "trimesh test models", MIT_TRIMESH, "CAD"),
    "quadknot": (TRIMESH, "models/quadknot.obj", "trimesh test models (a quad-meshed knot)",
                 MIT_TRIMESH, "modelled"),
    "round_stl": (TRIMESH, "models/round.stl", "trimesh test models", MIT_TRIMESH, "CAD"),
    "soup": (TRIMESH, "models/soup.stl", "trimesh test models (100 loose triangles)",
             MIT_TRIMESH, "CAD"),
    "tube": (TRIMESH, "models/tube.obj", "trimesh test models", MIT_TRIMESH, "CAD"),
    "ant": (PYVISTA, "pyvista/examples/ant.ply",
            "PyVista's built-in ant (examples.load_ant), from Greg Turk's PLY sample files",
            MIT_PYVISTA, "modelled"),
    "airplane": (PYVISTA, "pyvista/examples/airplane.ply",
                 "PyVista's built-in airplane (examples.load_airplane), from Greg Turk's PLY "
                 "sample files", MIT_PYVISTA, "modelled"),
}
"""The raw members: name -> ((repository, commit), path, author / origin, licence, kind)."""

GENERATED = {
    # name: (committed mesh, how, parameter)
    "kitten_decimated20": ("kitten", "decimate", 0.2),
    "blub_decimated20": ("blub", "decimate", 0.2),
    "bob_decimated20": ("bob", "decimate", 0.2),
    "spot_marching32": ("spot", "marching_cubes", 32),
    "double_torus_marching32": ("double_torus", "marching_cubes", 32),
    "rounded_cube_marching24": ("rounded_cube", "marching_cubes", 24),
}
"""Generated defects of the committed problem meshes: decimated to a share of
their triangles (libigl's shortest-edge collapse, ``igl.decimate``), or
resampled by marching cubes (``skimage.measure.marching_cubes``) of libigl's
signed distance on a grid of ``N`` cells along the longest side of the
bounding box padded by 2 cells."""


def _import(name, root):
    (repository, commit), path, *_ = SOURCES[name]
    if repository.startswith("pyvista"):
        data = Path(importlib.metadata.distribution("pyvista").locate_file(path)).read_bytes()
    else:
        git = Path(root) / repository.replace("/", "+") / "repo"
        data = subprocess.run(["git", "--git-dir", str(git), "show", f"{commit}:{path}"],
                              check=True, capture_output=True).stdout
    suffix = Path(path).suffix.lower()
    if len(data) <= KEEP_BYTES:
        return data, suffix, "none: the file's bytes as in the source"
    with tempfile.TemporaryDirectory() as tmp:
        src = Path(tmp) / f"source{suffix}"
        src.write_bytes(data)
        V, F = igl.read_triangle_mesh(str(src))[:2]
        polygons = read_mesh(src)[2].polygons
    single = bool(np.array_equal(V.astype(np.float32).astype(np.float64), V))
    split = f", its {polygons} polygons split by libigl's fan" if polygons else ""
    return (_ply_bytes(V, F, single), ".ply",
            f"converted to binary PLY ({len(data)} bytes as {suffix}): the vertices "
            f"({'float32, each exactly the value read' if single else 'float64'}) and triangles "
            f"as libigl reads the source{split}; nothing merged, dropped or reoriented")


def _ply_bytes(V, F, single=False):
    """Binary little-endian PLY of ``(V, F)``: vertices float32 (``single``) or
    float64, faces as a uchar count and int32 corners; no timestamp (meshio
    writes one), so the same mesh gives the same bytes."""
    kind, dtype = ("float", "<f4") if single else ("double", "<f8")
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(V)}\n"
              + "".join(f"property {kind} {axis}\n" for axis in "xyz")
              + f"element face {len(F)}\nproperty list uchar int vertex_indices\nend_header\n")
    faces = np.zeros(len(F), dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"], faces["v"] = 3, F
    return header.encode() + np.asarray(V, dtype).tobytes() + faces.tobytes()


def _generate(name):
    base, how, parameter = GENERATED[name]
    V, F = read_committed_mesh(base)
    if how == "decimate":
        target = int(round(parameter * len(F)))
        U, G = igl.decimate(np.asfortranarray(V), np.asfortranarray(F, dtype=np.int32), target)[:2]
        text = (f"decimated to {parameter:.0%} of its {len(F)} triangles ({target}) by libigl's "
                "shortest-edge collapse to the midpoint (igl.decimate)")
    else:
        from skimage.measure import marching_cubes

        lo, hi = V.min(axis=0), V.max(axis=0)
        cell = float((hi - lo).max()) / parameter
        axes = [np.arange(a - 2 * cell, b + 2.5 * cell, cell) for a, b in zip(lo, hi)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
        S = igl.signed_distance(grid.reshape(-1, 3), V, F)[0].reshape(grid.shape[:3])
        U, G = marching_cubes(S, level=0.0, spacing=(cell,) * 3)[:2]
        U = U + np.array([a[0] for a in axes])
        text = (f"resampled by marching cubes (skimage.measure.marching_cubes, level 0) of "
                f"libigl's signed distance on a grid of cell {cell:.6g} ({parameter} cells along "
                "the longest side, padded by 2)")
        if volume(U, G) < 0:
            G = G[:, ::-1]
            text += ", its triangles reversed to face outward"
    return _ply_bytes(U, G), f"generated from the committed mesh '{base}': {text}"


def describe(path):
    """The measured fields of one corpus file: the intake's outcome and, if it
    reads, counts, topology, quality and the thin-feature criterion."""
    data = path.read_bytes()
    out = {"sha256": hashlib.sha256(data).hexdigest(), "bytes": len(data)}
    try:
        V, F, report = read_mesh(path)
    except MeshError as err:
        return out | {"intake": "refused", "defect": err.kind}
    s = summarize(V, F)
    thin = thin_features(V, F)
    traits = [t for t, has in (
        ("open boundary", s.boundary_loops > 0), ("several components", s.components > 1),
        ("slivers", s.smallest_angle < SLIVER_DEGREES), ("thin features", thin.thin),
        ("polygons", report.polygons > 0), ("soup", report.merged > 0)) if has]
    return out | {
        "intake": "read", "defect": "", "repairs": report.notes(),
        "file_vertices": report.file_vertices, "file_faces": report.file_faces,
        "vertices": s.vertices, "faces": s.faces, "components": s.components,
        "boundary_loops": s.boundary_loops, "genus": sorted(set(s.genus)),
        "smallest_angle": round(s.smallest_angle, 4), "area_ratio": float(f"{s.area_ratio:.5g}"),
        "mean_edge": float(f"{thin.mean_edge:.6g}"),
        "thin_share": round(thin.thin_share, 5), "thin_features": thin.thin, "traits": traits}


def _row(name, e):
    if e["intake"] == "refused":
        counts = ["-"] * 6 + ["no (refused)"]
        outcome = f"refused: {e['defect']}"
    else:
        counts = [str(e["vertices"]), str(e["faces"]), str(e["components"]),
                  str(e["boundary_loops"]), ",".join(map(str, e["genus"])),
                  f"{e['smallest_angle']:.2f}",
                  f"{'yes' if e['thin_features'] else 'no'} ({e['thin_share']:.3f})"]
        outcome = "read" + (f" ({'; '.join(e['repairs'])})" if e["repairs"] else "")
    source = (f"{e['repository'].split(' ')[0]} `{e['path']}`" if e["origin"] == "raw"
              else e["processing"].split(":")[0])
    return (f"| `{e['file']}` | {e['origin']} | {e['kind']} | " + " | ".join(counts)
            + f" | {outcome} | {source} | {e['licence'].split(' (')[0]} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--import-from", metavar="ROOT",
                        help="copy the raw sources from git directories ROOT/<owner>+<name>/repo")
    args = parser.parse_args()
    manifest_path = RAW_DIR / "manifest.json"
    old = json.loads(manifest_path.read_text()) if manifest_path.exists() else {}
    manifest = {}
    for name, ((repository, commit), path, author, licence, kind) in SOURCES.items():
        if args.import_from:
            data, suffix, processing = _import(name, args.import_from)
            (RAW_DIR / f"{name}{suffix}").write_bytes(data)
        else:
            suffix, processing = Path(old[name]["file"]).suffix, old[name]["processing"]
        manifest[name] = {"file": f"{name}{suffix}", "origin": "raw", "repository": repository,
                          "path": path, "commit": commit, "author": author, "licence": licence,
                          "kind": kind, "processing": processing}
    for name, (base, _, _) in GENERATED.items():
        data, processing = _generate(name)
        (RAW_DIR / f"{name}.ply").write_bytes(data)
        entry = json.loads((RAW_DIR.parent / "meshes" / "manifest.json").read_text())[base]
        manifest[name] = {"file": f"{name}.ply", "origin": "generated",
                          "repository": entry["repository"], "path": entry["path"],
                          "commit": entry["commit"], "author": entry["author"],
                          "licence": entry["licence"], "kind": entry["kind"],
                          "processing": processing}
    for name, entry in manifest.items():
        entry |= describe(RAW_DIR / entry["file"])
    write_text(manifest_path, json.dumps(manifest, indent=1) + "\n")
    readme = (RAW_DIR / "README.md").read_text()
    head, rest = readme.split("<!-- table -->\n", 1)
    tail = rest.split("<!-- end of table -->", 1)[1]
    table = ["| file | origin | kind | vertices | faces | components | boundary loops | genus "
             "| smallest angle (deg) | thin features (share) | intake | source | licence |",
             "|" + "---|" * 13] + [_row(n, e) for n, e in manifest.items()]
    write_text(RAW_DIR / "README.md",
                      head + "<!-- table -->\n" + "\n".join(table) + "\n<!-- end of table -->" + tail)
    read = [e for e in manifest.values() if e["intake"] == "read"]
    print(f"{len(manifest)} files ({sum(e['origin'] == 'raw' for e in manifest.values())} raw), "
          f"{len(read)} read, {sum(e['thin_features'] for e in read)} with thin features "
          f"(share > {THIN_SHARE} thinner than {THICKNESS_FACTOR} h), "
          f"{sum(e['bytes'] for e in manifest.values())} bytes")


if __name__ == "__main__":
    main()
