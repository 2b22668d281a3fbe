"""Kovacs, Li, Lubich's scheme (:mod:`baselines.kll`)."""

from mcfbench.running.scheme import Scheme

ORDER = 70
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`)."""

SCHEME = Scheme("kll", "KLL", "baselines.kll:KLLFlow", {},
                {"color": "tab:purple", "marker": "*", "linestyle": "-"},
                "Kovacs, Li, Lubich (2019): normal and mean curvature evolved by Huisken's "
                "equations, velocity -H nu, P1 elements (the proof needs degree >= 2), the "
                "velocity law linearised at the extrapolated state", matrix="nonsymmetric",
                tangential="kll")
