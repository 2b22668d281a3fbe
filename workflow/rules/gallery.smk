# The gallery of real meshes (issue "Real meshes"): every scheme on every mesh
# file of a folder. Not part of `rule all`:
#
#   snakemake --cores 2 gallery                       # the suite's own meshes and the packaged real ones
#   snakemake --cores 2 gallery --config meshes=DIR   # every .obj .off .ply .stl in DIR
#
# Each run: the mesh read by mcfbench.geometry.mesh_files.read_mesh (repaired and
# validated), tau = C * (mean edge length)^2, `steps` steps, the robust solver
# (config key `gallery`). Without `meshes` the suite first writes its own
# real-world-like meshes and the real meshes shipped inside pinned packages
# (mcfbench.geometry.packaged_meshes: pyvista, nilearn; read from the installed
# package, SHA-256 checked) as OBJ to results/gallery/meshes/.
#
# Its runs are specs in the run store (a mesh file's path and SHA-256 in each;
# about 20 frames each; workflow/rules/runs.smk). Outputs under results/gallery/
# (the paths: mcfbench/studies/gallery/__init__.py): movies/{mesh}/{scheme}.gif,
# table.md, table.csv, pictures.png, pictures.pdf.

import mcfbench.studies.gallery as _gallery
from mcfbench.pipeline import alternatives as _alternatives

# the plan; without meshes (no runs) when the section `gallery` or `meshes` is
# bad: then `snakemake gallery` names the bad key (rule gallery)
GALLERY = PLANS.while_reading("gallery", {"meshes": {}, "generated": {}, "schemes": []})
GALLERY_MOVIES = [
    _gallery.MOVIE.format(mesh=mesh, scheme=scheme)
    for mesh in GALLERY["meshes"]
    for scheme in GALLERY["schemes"]
]
GALLERY_TARGETS = [
    f"{_gallery.TABLE}.md",
    f"{_gallery.TABLE}.csv",
    f"{_gallery.PICTURES}.png",
    f"{_gallery.PICTURES}.pdf",
    *GALLERY_MOVIES,
]


if GALLERY["generated"]:

    rule gallery_mesh:
        """One of the suite's own meshes, or a packaged real mesh, as OBJ (when no
        `meshes` folder is given)."""
        output:
            _gallery.MESH,
        log:
            "results/logs/gallery/meshes/{mesh}.log",
        benchmark:
            "results/benchmarks/gallery/meshes/{mesh}.tsv"
        wildcard_constraints:
            mesh=_alternatives(GALLERY["generated"]),
        conda:
            "../envs/ddfv.yaml"
        threads: 1
        resources:
            mem_mb=1000,
            runtime=10,
        params:
            entry=lambda wildcards: GALLERY["generated"][wildcards.mesh],
            code=PLANS.code,
        script:
            "../scripts/gallery_mesh.py"


# One batch per mesh file: every scheme on it (the run store's job,
# workflow/scripts/run_batch.py); its specs, with the file's SHA-256, are made when
# the batch joins the job graph (the suite's own meshes are written by gallery_mesh).
for _k, _mesh in enumerate(GALLERY["meshes"], start=1):

    rule:
        name:
            f"runs_gallery_batch{_k}"
        input:
            kernels=ancient(KERNELS),
            mesh=GALLERY["meshes"][_mesh],
        output:
            _manifest_path(f"gallery_batch{_k}"),
        log:
            f"results/logs/runs/gallery_batch{_k}.log",
        benchmark:
            f"results/benchmarks/runs/gallery_batch{_k}.tsv"
        conda:
            "../envs/ddfv.yaml"
        threads: 1
        resources:
            mem_mb=2000,
            runtime=60 * len(GALLERY["schemes"]),
        params:
            runs=gallery_batch_runs(_mesh),
        script:
            "../scripts/run_batch.py"


rule gallery_table:
    """Mesh x scheme: status, steps, breakdown time, mesh quality, CPU time."""
    input:
        gallery_runs,
    output:
        md=f"{_gallery.TABLE}.md",
        csv=f"{_gallery.TABLE}.csv",
    log:
        "results/logs/gallery/table.log",
    benchmark:
        "results/benchmarks/gallery/table.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=5,
    params:
        plan=GALLERY,
    script:
        "../scripts/gallery_table.py"


rule gallery_pictures:
    """Per mesh the initial surface and every scheme's last frame."""
    input:
        gallery_runs,
    output:
        png=f"{_gallery.PICTURES}.png",
        pdf=f"{_gallery.PICTURES}.pdf",
    log:
        "results/logs/gallery/pictures.log",
    benchmark:
        "results/benchmarks/gallery/pictures.tsv"
    localrule: True
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=2000,
        runtime=10,
    params:
        plan=GALLERY,
    script:
        "../scripts/gallery_pictures.py"


rule gallery_movie:
    """One run's frames as an animated GIF (one camera, time and status per frame)."""
    input:
        gallery_runs,
    output:
        gif=_gallery.MOVIE,
    log:
        "results/logs/gallery/movies/{mesh}/{scheme}.log",
    benchmark:
        "results/benchmarks/gallery/movies/{mesh}/{scheme}.tsv"
    wildcard_constraints:
        mesh=_alternatives(GALLERY["meshes"]),
        scheme=_alternatives(GALLERY["schemes"]),
    conda:
        "../envs/ddfv.yaml"
    threads: 1
    resources:
        mem_mb=1000,
        runtime=10,
    params:
        plan=GALLERY,
    script:
        "../scripts/gallery_movie.py"


rule gallery:
    """Target: every scheme on every mesh file (`--config meshes=DIR`; default the
    suite's own meshes), table and pictures in results/gallery/."""
    input:
        # the plan first: a bad value under `gallery` is named here
        lambda wildcards: PLANS.checked("gallery", GALLERY_TARGETS),
    localrule: True
