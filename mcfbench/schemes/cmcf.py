"""Conformalized mean curvature flow (:mod:`baselines.cmcf`)."""

from mcfbench.running.scheme import Scheme

ORDER = 30
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`)."""

SCHEME = Scheme("cmcf", "conformalized MCF", "baselines.cmcf:CMCFFlow", {"mass": "barycentric"},
                {"color": "C6", "marker": ">", "linestyle": "-."},
                "conformalized mean curvature flow (Kazhdan, Solomon, Ben-Chen 2012): initial "
                "stiffness kept, mass rebuilt, no rescaling", matrix="scaled-spd",
                tangential="conformal")
