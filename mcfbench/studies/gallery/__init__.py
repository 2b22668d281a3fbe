"""The gallery: every scheme on every mesh file of a folder (default: the suite's generated
real-world-like meshes and the real meshes shipped inside pinned packages,
:data:`mcfbench.geometry.packaged_meshes.PACKAGED_MESHES`), one run job per (mesh, scheme).

The study's modules (``workflow/rules/gallery.smk`` calls them): :mod:`.plan`
(the config keys ``gallery`` and ``meshes``, the suite's own meshes),
:mod:`.job` (one scheme on one mesh file, and the OBJ files of the suite's
meshes), :mod:`.tables` (mesh x scheme) and :mod:`.plots` (the picture grid,
one animation per run)."""
