"""Discrete duality finite volume (DDFV) scheme for mean curvature flow of surfaces.

The scheme of the paper, read in its order: :mod:`ddfv.topology` (the
diamond mesh, 2.2.2) -> :mod:`ddfv.geometry` (per-diamond quantities,
2.2.3-2.2.5) -> :mod:`ddfv.t_vertices` (initial T-vertices, Section 3) ->
:mod:`ddfv.assembly` (the system (2.10)-(2.15)) -> :mod:`ddfv.flow`
(semi-implicit steps (2.1), Dirichlet boundary (1.2), elimination (3.6),
the journal version's tangential redistribution :mod:`ddfv.redistribution`)
with its named :mod:`ddfv.variants`.

This package is the scheme only: it imports nothing from the harness
(``mcfbench``, which runs it: solver, driver, problems, studies) or from
``baselines``.

Public API
----------
Flow(vertices, faces, tau, **options)
    One DDFV flow; ``flow.system(at, base, dt)`` is the linear system of one
    time step with its operators at the state ``at`` (the paper's step:
    ``flow.system()``), ``flow.advance(X)`` accepts its solution.
VARIANTS, variant_options(name)
    Named variants of the scheme (paper, chord, eliminate, chord-eliminate,
    redistribute, chord-redistribute, chord-carried, chord-redistribute-carried).
DiamondMesh, diamond_mesh(faces)
    The diamond mesh (Section 2.2.2).
"""

import importlib

_EXPORTS = {"Flow": "flow", "DiamondMesh": "topology", "diamond_mesh": "topology",
            "VARIANTS": "variants", "variant_options": "variants"}
__all__ = sorted(_EXPORTS)


def __getattr__(name):
    """The public names on first use: ``import ddfv.topology`` (a picture of the
    diamond mesh) loads neither the flow nor its compiled kernels (numba)."""
    if name in _EXPORTS:
        return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    raise AttributeError(f"module 'ddfv' has no attribute {name!r}")
