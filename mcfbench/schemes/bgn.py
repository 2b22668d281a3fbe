"""Barrett, Garcke, Nuernberg's scheme (:mod:`baselines.bgn`)."""

from mcfbench.running.scheme import Scheme

ORDER = 40
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`)."""

SCHEME = Scheme("bgn", "BGN", "baselines.bgn:BGNFlow", {"scaling": "mass"},
                {"color": "C7", "marker": "P", "linestyle": ":"},
                "Barrett, Garcke, Nuernberg (2008): mass-lumped vertex normals, tangential "
                "motion that equidistributes the mesh", matrix="scaled-spd", tangential="bgn")
