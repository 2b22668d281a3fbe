"""The schemes this package brings to mcfbench (entry point ``mcfbench.schemes``)."""

from mcfbench.running.scheme import Scheme

SCHEMES = [Scheme("cotan-consistent", "cotangent, consistent mass",
                  "mcfplugin.flow:ConsistentCotanFlow",
                  style={"color": "tab:pink", "marker": "o", "linestyle": "-"},
                  description="the cotangent scheme with the consistent P1 mass (Dziuk 1991)",
                  matrix="scaled-spd")]
