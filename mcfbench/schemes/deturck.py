"""The DeTurck trick (:mod:`baselines.deturck`)."""

from mcfbench.running.scheme import Scheme

ORDER = 60
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`)."""

SCHEME = Scheme("deturck", "DeTurck", "baselines.deturck:DeTurckFlow", {"alpha": 0.1},
                {"color": "tab:brown", "marker": "H", "linestyle": "--"},
                "the DeTurck trick (Elliott, Fritz 2017): reparametrised by the harmonic map heat "
                "flow onto the initial mesh with time scale 1/alpha, the advection implicit",
                matrix="nonsymmetric", tangential="deturck")
