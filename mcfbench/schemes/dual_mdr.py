"""The dual-MDR scheme (:mod:`baselines.dual_mdr`)."""

from mcfbench.running.scheme import Scheme

ORDER = 55
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`): after MDR."""

SCHEME = Scheme("dual-mdr", "dual-MDR", "baselines.dual_mdr:DualMDRFlow", {"scaling": "mass"},
                {"color": "teal", "marker": "o", "linestyle": "--"},
                "dual-MDR (Gao, Li, Tang 2026): MDR's tangential motion with a tangential dual "
                "multiplier R that makes the area decrease at every step, (X, R) in one block "
                "triangular system", matrix="nonsymmetric", tangential="dual-mdr")
