"""BGN with BDF-k in time as Jiang, Su and Zhang (2024) build it (:mod:`baselines.bgn_bdf`):
its own entries, not what ``bgn@bdf2`` means (``baselines/README.md``)."""

from mcfbench.running.scheme import Scheme

ORDER = 45
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`): after BGN."""

START = {2: {}, 3: {"start": "equilibrium"}}
"""Each order's start (``baselines/README.md``, bgn-bdf3): BDF3 needs ``X^1`` to
O(tau^3) and its history at BGN's tangential equilibrium; BDF2 neither (the flow's
default, BGN's first step)."""

SCHEMES = [Scheme(f"bgn-bdf{k}", f"BGN/BDF{k}", "baselines.bgn_bdf:BGNBDFFlow",
                  {"order": k, **START[k], "scaling": "mass"},
                  {"color": "C7", "marker": marker, "linestyle": "-."},
                  f"BGN with BDF{k} in time as Jiang, Su and Zhang (2024) build it: the normals "
                  f"and inner products on a predictor surface from BGN/BDF1..{k - 1} solves, "
                  f"{k} solves a step", matrix="scaled-spd", tangential="bgn",
                  integrates_itself=True)
           for k, marker in ((2, "1"), (3, "2"))]
