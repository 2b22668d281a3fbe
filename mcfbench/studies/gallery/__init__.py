"""The gallery: every scheme on every mesh file of a folder (default: the suite's generated
real-world-like meshes and the real meshes shipped inside pinned packages,
:data:`mcfbench.geometry.packaged_meshes.PACKAGED_MESHES`), one run per (mesh, scheme) in the run store.

The study's modules (``workflow/rules/gallery.smk`` calls them): :mod:`.plan`
(the config keys ``gallery`` and ``meshes``, the suite's own meshes),
:mod:`.job` (the OBJ files of the suite's meshes), :mod:`.tables` (mesh x scheme) and :mod:`.plots` (the picture grid,
one animation per run)."""

ROOT = "results/gallery"
"""The folder of the study's outputs; every path below is a pattern of ``{mesh}``
(a file name) and ``{scheme}`` (a registry name), as Snakemake's wildcards."""

MESH = f"{ROOT}/meshes/{{mesh}}"
"""One of the suite's own meshes written as OBJ (when no ``meshes`` folder is given)."""

MOVIE = f"{ROOT}/movies/{{mesh}}/{{scheme}}.gif"
"""One run's animation."""

TABLE = f"{ROOT}/table"
"""Mesh x scheme, ``.md`` and ``.csv``."""

PICTURES = f"{ROOT}/pictures"
"""Per mesh the initial surface and every scheme's last frame, ``.png`` and ``.pdf``."""
