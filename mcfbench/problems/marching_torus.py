"""Marching cubes of a tilted torus (genus 1); tau = 0.1 h^2, 40 steps."""

from mcfbench.running.problem import Problem

ORDER = 13
"""Its place among the built-in problems (:mod:`mcfbench.running.discovery`)."""

PROBLEM = Problem("marching_torus", "marching-cubes torus (genus 1)", "implicit_torus",
                  lambda level: {"resolution": 24 * 2 ** int(level)},
                  levels=(1,), tau_1=0.1, t_final=0.0, metrics=("shape",), tau_rule="mesh", steps=40,
                  exact="no exact solution: smoothing of a scanned-like mesh",
                  kind="real_world", main_metric="volume",
                  description="Marching cubes of a tilted torus (genus 1); tau = 0.1 h^2, 40 steps.")
