"""The minimal deformation rate scheme (:mod:`baselines.mdr`)."""

from mcfbench.running.scheme import Scheme

ORDER = 50
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`)."""

SCHEME = Scheme("mdr", "MDR", "baselines.mdr:MDRFlow", {"scaling": "mass"},
                {"color": "tab:cyan", "marker": "d", "linestyle": "-"},
                "minimal deformation rate (Hu, Li 2022): the velocity of least int |grad v|^2 with "
                "normal part -H, the multiplier eliminated into BGN's system with unit normals",
                matrix="scaled-spd", tangential="mdr")
