"""Geometry: initial surfaces, mesh intake and validation, metrics, exact solutions and mesh-quality monitors.

Rule: functions of a mesh; imports ``storage`` at most, never ``running``, ``presentation`` or ``studies``.
"""
