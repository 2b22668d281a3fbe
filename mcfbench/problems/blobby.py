"""Marching cubes of a sum of metaballs: irregular valences and slivers as in scanned
meshes; tau = 0.1 h^2, 40 steps."""

from mcfbench.running.problem import Problem

ORDER = 12
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("blobby", "marching-cubes blob (genus 0)", "blobby",
                  lambda level: {"resolution": 20 * 2 ** int(level)},
                  levels=(1,), tau_1=0.1, t_final=0.0, metrics=("shape",), tau_rule="mesh", steps=40,
                  exact="no exact solution: smoothing of a scanned-like mesh",
                  kind="real_world", main_metric="volume",
                  description="Marching cubes of a sum of metaballs: irregular valences and slivers "
                              "as in scanned meshes; tau = 0.1 h^2, 40 steps.")
