"""Baseline schemes compared with the DDFV scheme.

Every scheme is a module exposing ``sphere_run(level, *, tau, t_final,
radius, rtol, ...) -> ddfv.sphere.SphereRun`` (see ``baselines/README.md``).

cotan
    The classical cotangent scheme (libigl's ``cotmatrix`` / ``massmatrix``).
"""
