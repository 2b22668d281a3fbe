"""Running: the flow contract, the registries of schemes and problems, the shared solver, the driver and the one ``run`` of a scheme on a problem.

Rule: imports ``geometry``, ``storage``, the scheme packages and the folders of declarations it
scans (``mcfbench.schemes``, ``mcfbench.problems``), never ``presentation`` or ``studies``.
"""
