"""Discrete duality finite volume (DDFV) scheme for mean curvature flow of surfaces.

Public API
----------
simulate(vertices, faces, tau, steps, ...) -> Trajectory
    Run the flow (Sections 2-3 of the paper).
Flow
    One flow, stepped by hand.
sphere_run(level, ...) -> SphereRun
    One row of Table 3.1.
icosphere(level), diamond_mesh(faces), read_mesh(path)
SphereL2Error, eoc, sphere_radius
    The error (3.2), the order (3.1) and the exact solution.
VARIANTS, variant_options(name)
    Named variants of the scheme (paper, chord, eliminate).
"""

from .memory import tune_malloc

tune_malloc()

from .errors import SphereL2Error, eoc, sphere_radius  # noqa: E402
from .meshio import read_mesh  # noqa: E402
from .sphere import SphereRun, sphere_run  # noqa: E402
from .stepping import Flow, FlowBreakdown, Trajectory, simulate  # noqa: E402
from .surfaces import icosphere  # noqa: E402
from .topology import DiamondMesh, diamond_mesh  # noqa: E402
from .variants import VARIANTS, variant_options  # noqa: E402

__all__ = [
    "DiamondMesh", "Flow", "FlowBreakdown", "SphereL2Error", "SphereRun",
    "Trajectory", "diamond_mesh", "eoc", "icosphere", "read_mesh", "simulate",
    "sphere_radius", "sphere_run", "VARIANTS", "variant_options",
]
