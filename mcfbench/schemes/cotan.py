"""The cotangent scheme (Dziuk 1991) and its variants: lumped masses, intrinsic Delaunay
operators, area redistribution (:mod:`baselines.cotan`, :mod:`baselines.cotan_intrinsic`)."""

from mcfbench.running.scheme import Scheme

ORDER = 20
"""Its place among the built-in schemes (:mod:`mcfbench.running.discovery`)."""

SCHEMES = [
    Scheme("cotan", "cotangent", "baselines.cotan:CotanFlow", {"mass": "barycentric"},
           {"color": "C3", "marker": "v", "linestyle": "-"},
           "the cotangent scheme (Dziuk 1991), barycentric lumped mass", matrix="scaled-spd"),
    Scheme("cotan-voronoi", "cotangent, Voronoi mass", "baselines.cotan:CotanFlow",
           {"mass": "voronoi"}, {"color": "C5", "marker": "<", "linestyle": "--"},
           "the cotangent scheme (Dziuk 1991), Voronoi (mixed) lumped mass (Meyer et al. 2003)",
           matrix="scaled-spd"),
    Scheme("cotan-intrinsic", "cotangent, intrinsic Delaunay",
           "baselines.cotan_intrinsic:IntrinsicCotanFlow", {},
           {"color": "tab:brown", "marker": "d", "linestyle": "-."},
           "the cotangent scheme (Dziuk 1991) with the stiffness and barycentric mass of the "
           "intrinsic Delaunay triangulation (Sharp, Crane 2020; robust-laplacian), rebuilt "
           "every step", matrix="scaled-spd",
           tangential="intrinsic-delaunay"),
    Scheme("cotan-redistribute", "cotangent, area redistribution", "baselines.cotan:CotanFlow",
           {"mass": "barycentric", "redistribution": "area", "target": "triangle"},
           {"color": "tab:olive", "marker": "P", "linestyle": "--"},
           "the cotangent scheme (Dziuk 1991) with the area-oriented tangential redistribution "
           "of Mikula, Remesikova, Sarkoci, Sevcovic (2014), semi-implicit (the advection "
           "grad psi . grad X in the matrix, Scharfetter-Gummel weights, Peclet limit 0.1), "
           "omega = 10, toward the areas of equal-area triangles (half at a fixed boundary)",
           matrix="nonsymmetric", tangential="redistribute"),
]
