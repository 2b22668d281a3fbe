"""Storage: run records and their schema, the statuses a run ends with, provenance, atomic writes, the frame files and process memory.

Rule: imports nothing of ``running``, ``geometry``, ``presentation`` or ``studies``, and no compiled kernel.
"""
