"""The committed real meshes as problems: one problem ``real_<name>`` per mesh of
``mcfbench/data/meshes`` with a reference file, in the manifest's order
(:mod:`mcfbench.running.real_mesh_problems`).

One module declares them all: they are generated from the manifest and the
reference files, so a new real mesh is its committed file, its manifest entry and
its reference file (``benchmarks/real_mesh_references.py``), no Python. Each
problem's ``data_files`` are its own mesh and reference files, so that a new or
remade reference changes the runs of that mesh only.
"""

from mcfbench.running.real_mesh_problems import RealMeshShape, real_mesh_problems

ORDER = 100
"""After the generated surfaces."""

PROBLEMS = list(real_mesh_problems().values())

METRICS = {"real_mesh": RealMeshShape}
"""The observer of every real-mesh problem."""
