"""The reference answers of the real-mesh problems, as the problems read them
(``mcfbench/data/meshes/references/<name>.json``, :mod:`mcfbench.running.real_mesh_problems`).

    nice python benchmarks/real_mesh_references.py                 # every mesh, about 12 min CPU
    nice python benchmarks/real_mesh_references.py --mesh nut spot # some meshes

For each committed mesh: the mean edge ``h_0`` of level 0 of its Loop-limit
series, ``tau_0 = 0.1 h_0^2``; the cotangent scheme (Dziuk's) and BGN's on
levels ``0..L`` (``tau_l = tau_0 / 4^l``, the direct solver) to the horizon
``10 tau_0``; then the first singularity, ``t_final = N tau_0`` before it, the
reference area and volume at ``t = j tau_0`` (``j = 1..N``) with their
accuracy and the orders observed
(:mod:`mcfbench.running.two_scheme_references`). Levels: the cotangent
scheme to ``L = 2`` on meshes of at most :data:`FINE_LIMIT` vertices, else
``L = 1``; BGN (a saddle-point system four times the size, about 10x the
cotangent scheme's time: 38 s CPU for level 1 of spot, 11 714 vertices, 40
steps) to ``L = 1`` on meshes of at most :data:`BGN_LIMIT` vertices, else
level 0 only (the budget: about 15 min CPU for twelve meshes of up to 10 044
vertices on a shared 2-core machine), unless the
cotangent scheme broke down before the horizon: BGN then carries the
reference alone after the breakdown and runs level 1 too.
Then the reference surface at ``t_final`` and the accuracy of the distance
to it (:func:`mcfbench.running.two_scheme_references.distance_answers`):
the finest cotangent run's vertex positions at ``t_final`` are stored in
``references/<name>.npz`` (float32, see :mod:`mcfbench.running.real_mesh_problems`),
its faces are the level's, regenerated from the committed mesh (their
SHA-256 is stored in the JSON). ``--reuse-runs`` recomputes the answers from
the runs stored in the reference files and runs only those the rule above
adds and those whose final surfaces the distance needs (the two finest
levels of each scheme: positions are not stored in the JSON). One JSON and
one NPZ per mesh, written atomically, the JSON with the command that remakes
both. Prints the table of all meshes.
"""

import argparse
import json
import math
import os
import shlex
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

from mcfbench.geometry.committed_meshes import mesh_manifest, real_mesh  # noqa: E402
from mcfbench.geometry.metrics import mean_edge_length  # noqa: E402
from mcfbench.running.real_mesh_problems import (  # noqa: E402
    SURFACE_DTYPE,
    TAU_EDGE,
    faces_digest,
    real_mesh_problem,
    reference_path,
    surface_path,
)
from mcfbench.running.two_scheme_references import (  # noqa: E402
    QUANTITIES,
    distance_answers,
    reference_answers,
    reference_runs,
)
from mcfbench.storage.atomic import save_npz, write_json  # noqa: E402

HORIZON = 10
"""Checkpoints searched: ``t = j tau_0``, ``j <= HORIZON``."""
FINE_LIMIT = 3000
"""Largest level-0 vertex count run on level 2 (by the cotangent scheme)."""
BGN_LIMIT = 7200
"""Largest level-0 vertex count BGN runs on level 1."""


def scheme_levels(vertices):
    """The levels of each scheme for a mesh of ``vertices`` vertices (see the module docstring)."""
    return {"cotan": (0, 1, 2) if vertices <= FINE_LIMIT else (0, 1),
            "bgn": (0, 1) if vertices <= BGN_LIMIT else (0,)}


def mesh_reference(name, stored=None):
    """The reference file's content for the committed mesh ``name`` (from the
    runs of the ``stored`` content, if given, and the runs it lacks), and the
    reference surface's vertex positions at ``t_final`` (``None`` if ``N = 0``)."""
    cpu = time.process_time()
    V, F = real_mesh(name, 0)
    h0 = mean_edge_length(V, F)
    tau_0 = TAU_EDGE * h0 ** 2
    levels = scheme_levels(len(V))
    provisional = real_mesh_problem(name, {"h0": h0, "steps": HORIZON, "checkpoints": [],
                                           "levels": list(levels["cotan"])})
    if stored is None:
        runs = reference_runs(provisional, levels, tau_0, HORIZON)
    else:
        runs = [{**r, **{q: [math.nan if x is None else x for x in r[q]] for q in QUANTITIES}}
                for r in stored["runs"]]
        cpu -= stored["cpu_seconds"]
    if len(levels["bgn"]) == 1 and any(r["status"] != "ok" for r in runs
                                       if r["scheme"] == "cotan"):
        # the cotangent scheme broke down: BGN carries the reference alone
        # after it, so it needs two levels for an error estimate
        levels = {**levels, "bgn": (0, 1)}
    # the distance needs the final surfaces of each scheme's two finest runs
    finest = {(s, lv) for s, ls in levels.items() for lv in ls[-2:]}
    cpu += sum(r["cpu_seconds"] for r in runs
               if (r["scheme"], r["level"]) in finest and "surface" not in r)
    runs = [r for r in runs if (r["scheme"], r["level"]) not in finest or "surface" in r]
    have = {(r["scheme"], r["level"]) for r in runs}
    for scheme, wanted in levels.items():
        missing = tuple(lv for lv in wanted if (scheme, lv) not in have)
        if missing:
            runs += reference_runs(provisional, {scheme: missing}, tau_0, HORIZON, level_0=0)
    runs.sort(key=lambda r: (list(levels).index(r["scheme"]), r["level"]))
    answers = reference_answers(runs, tau_0, HORIZON)
    distance, surface = ({}, None) if not answers["steps"] else \
        distance_answers(runs, answers, tau_0)
    if surface is not None:
        distance["distance_reference"].update(file=surface_path(name).name,
                                              dtype=SURFACE_DTYPE,
                                              faces_sha256=faces_digest(surface[1]))
    return {"mesh": name,
            "command": f"nice python benchmarks/real_mesh_references.py --mesh {shlex.quote(name)}",
            "h0": h0, "tau0": tau_0, "t_final": answers["steps"] * tau_0,
            "levels": list(levels["cotan"]), "scheme_levels": levels,
            "vertices": {str(r["level"]): r["vertices"] for r in runs},
            **answers, **distance,
            "runs": [{k: v for k, v in r.items() if k != "surface"} for r in runs],
            "cpu_seconds": time.process_time() - cpu}, None if surface is None else surface[0]


def _distance_cell(ref):
    """The distance accuracy of a reference, with its level and scheme parts."""
    if "distance_accuracy" not in ref:
        return "-"
    surface = ref["distance_reference"]
    parts = [f"{ref[f'distance_{k}_difference']:.1e}" if ref[f"distance_{k}_difference"]
             is not None else "-" for k in ("level", "scheme")]
    return (f"{ref['distance_accuracy']:.1e} ({'; '.join(parts)}; reference "
            f"{surface['scheme']} {surface['level']}, L = {ref['length_scale']:.4g})")


def table(references):
    """Markdown table: one row per mesh."""
    rows = ["| mesh | vertices per level | N | t_final | area (accuracy) | volume (accuracy) "
            "| first singularity; runs that broke down | observed orders (area, volume) "
            "| schemes at t_final | cotan vs bgn | distance accuracy / L (levels; schemes) |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, ref in references.items():
        verts = ", ".join(f"{v}" for _, v in sorted(ref["vertices"].items()))
        levels = "; ".join(f"{s} {','.join(map(str, ls))}"
                           for s, ls in ref["scheme_levels"].items())
        sing = ref["singularity"]
        when = f"{sing['time']:.3g}" if sing["time"] is not None else \
            f"none before {sing['searched_to']:.3g}"
        broke = ", ".join(f"{b['scheme']} {b['level']} {b['status']} at "
                          f"{b['t_end'] / ref['tau0']:.3g} tau_0" for b in sing["breakdowns"])
        orders = "; ".join(
            f"{s}: " + ", ".join(f"{x:.2f}" for q in ("area", "volume")
                                 for x in o[q]["observed"]) for s, o in ref["orders"].items()
            if o["area"]["observed"])
        disagree = {q: ref[f"{q}_disagree"] for q in ("area", "volume") if ref[f"{q}_disagree"]}
        if not ref["steps"]:
            rows.append(f"| {name} | {verts} ({levels}) | 0 | - | - | - | {when}"
                        f"{'; ' + broke if broke else ''} | - | - | no checkpoint: not a problem "
                        "| - |")
            continue
        rows.append(
            f"| {name} | {verts} ({levels}) | {ref['steps']} | {ref['t_final']:.4g} "
            f"| {ref['area'][-1]:.7g} ({ref['area_accuracy'][-1]:.1e}) "
            f"| {ref['volume'][-1]:.7g} ({ref['volume_accuracy'][-1]:.1e}) "
            f"| {when}{'; ' + broke if broke else ''} | {orders or '-'} "
            f"| {', '.join(ref['area_schemes'][-1])} "
            f"| {'disagree at ' + str(disagree) if disagree else 'agree'} "
            f"| {_distance_cell(ref)} |")
    return "\n".join(rows)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--mesh", nargs="+", default=list(mesh_manifest()),
                        choices=list(mesh_manifest()))
    parser.add_argument("--reuse-runs", action="store_true",
                        help="recompute the answers from the runs stored in the reference files")
    parser.add_argument("--table-only", action="store_true",
                        help="print the table of the stored references")
    args = parser.parse_args(argv)
    references = {}
    for name in args.mesh:
        if not args.table_only:
            stored = json.loads(reference_path(name).read_text()) if args.reuse_runs else None
            ref, surface = mesh_reference(name, stored)
            if surface is not None:
                save_npz(surface_path(name), vertices=surface.astype(SURFACE_DTYPE))
            write_json(reference_path(name), ref)
            print(f"{name}: {ref['cpu_seconds']:.0f} s CPU, N = {ref['steps']}", file=sys.stderr,
                  flush=True)
            if not ref["steps"]:
                print(f"{name}: every reference run broke down before t = tau_0: no checkpoint, "
                      "so the mesh is no problem (real_mesh_problems skips it)", file=sys.stderr)
        references[name] = json.loads(reference_path(name).read_text())
    print(table(references))


if __name__ == "__main__":
    main()
