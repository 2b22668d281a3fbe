"""The built-in problems, one module each, found by the registry.

A module of this package is one problem (the committed real meshes: one module
for all, :mod:`.real_meshes`). It defines

* ``PROBLEM``: its :class:`mcfbench.running.problem.Problem` (name, label, the
  surface's name and parameters per level, levels, time rule, metrics, the exact
  or reference answer, its ``kind`` and ``main_metric``, the ``data_files`` it
  reads), or ``PROBLEMS``, a list of them;
* ``ORDER``: an integer, its place among the built-ins (a module without one comes
  last; :mod:`mcfbench.running.discovery`);
* optionally ``surface(**params)``: the generator of its initial surface,
  registered under ``PROBLEM.surface`` (:data:`mcfbench.geometry.surfaces.SURFACES`)
  unless a surface of that name exists;
* optionally ``METRICS``: observer name -> class (``cls(problem)``, called with the
  flow after every step, ``result()`` -> ``{metric: value}``), registered in
  :data:`mcfbench.running.observers.METRICS`.

Its main metric (the matrix's summary, plots and findings) is ``PROBLEM.main_metric``;
what it tests (exact answer, reference answer, real-world-like mesh, committed real
mesh) is ``PROBLEM.kind`` (:data:`mcfbench.running.problem.KINDS`). Its view (the
camera of its pictures) is the presentation's
(:data:`mcfbench.studies.matrix.plots.VIEWS`), so that changing it reruns nothing.

:func:`mcfbench.running.problems.discover_problems` imports every module here when
the registry is first imported; adding a problem is adding a file, no other file
edited. Modules import ``storage``, ``geometry``, :mod:`mcfbench.running.problem`,
:mod:`mcfbench.running.observers` and :mod:`mcfbench.running.real_mesh_problems` at
most, never the registry.
"""
