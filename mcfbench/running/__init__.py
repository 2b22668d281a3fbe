"""Running: the flow contract, the registries of schemes and problems, the shared solver, the driver and the one ``run`` of a scheme on a problem.

Rule: imports ``geometry``, ``storage`` and the scheme packages, never ``presentation`` or ``studies``.
"""
