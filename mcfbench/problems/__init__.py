"""Problems as drop-in modules: one file per problem, found by the registry.

A module of this package is one problem. It defines

* ``PROBLEM``: its :class:`mcfbench.running.problems.Problem` (name, label, the
  surface's name and parameters per level, levels, time rule, metrics, the exact
  or reference answer; ``tau_rule = "mesh"`` for a mesh without a refinement
  series: the robust solver, a real-world-like mesh of the matrix);
* optionally ``surface(**params)``: the generator of its initial surface,
  registered under ``PROBLEM.surface`` (:data:`mcfbench.geometry.surfaces.SURFACES`)
  unless a surface of that name exists;
* optionally ``METRICS``: observer name -> class (``cls(problem)``, called with the
  flow after every step, ``result()`` -> ``{metric: value}``), registered in
  :data:`mcfbench.running.problems.METRICS`.

Its main metric (the matrix's summary, plots and findings) is ``PROBLEM.main_metric``.

:func:`mcfbench.running.problems.discover_problems` imports every module here when
the registry is first imported; adding a problem is adding a file, no other file
edited. Modules import ``storage``, ``geometry`` and ``mcfbench.running.problems``
at most (the registry's layer).
"""
