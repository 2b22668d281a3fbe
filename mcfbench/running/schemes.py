"""The registry of schemes: name -> flow class, options, label and plot style.

One entry per scheme; the command line, the studies, the pipeline, the
tables, the figures and the report all look schemes up here, so a new
scheme is one module (a class following :class:`mcfbench.running.flow.SchemeFlow`) plus
one entry of :data:`SCHEMES`. The flow class is named as
``"module:Class"`` and imported on first use.

The DDFV variants are entries ``ddfv``, ``ddfv-<variant>`` with the options
of :data:`ddfv.variants.VARIANTS`.

Every scheme is stepped by the paper's semi-implicit Euler step unless
asked otherwise; ``<name>@<integrator>`` (e.g. ``cotan@bdf2``) names the
scheme ``<name>`` stepped by another integrator of
:data:`mcfbench.running.integrators.INTEGRATORS` (:func:`get_scheme`), so
that a study lists it like any scheme (the matrix, the beyond study).
"""

import importlib
import inspect
from dataclasses import dataclass, field, replace

from mcfbench.running.integrators import INTEGRATORS

MATRICES = {
    "nonsymmetric": "BiCGStab (the paper's) or a sparse LU (`direct`): the matrix is not "
                    "symmetric, nor a diagonal scaling of a symmetric one",
    "scaled-spd": "conjugate gradients or Cholesky on the symmetric form (each row times "
                  "its lumped mass): the matrix is a row scaling of a symmetric positive "
                  "definite one on a closed surface (the Dirichlet rows of an open one "
                  "break the symmetry unless eliminated); of the shared solver's methods, "
                  "BiCGStab or `direct` (it has no CG)",
}
"""Kinds of linear system -> the solver that suits it (:attr:`Scheme.matrix`)."""


TANGENTIAL = {
    "none": "the normal velocity only (DDFV's T-vertices by the scheme or carried)",
    "eliminate": "the paper's elimination of the tangential velocity (3.6)",
    "redistribute": "area-oriented redistribution (Mikula, Remesikova, Sarkoci, Sevcovic "
                    "2014; the journal version)",
    "bgn": "BGN's equidistribution (Barrett, Garcke, Nuernberg 2008)",
    "mdr": "minimal deformation rate (Hu, Li 2022)",
    "deturck": "DeTurck (Elliott, Fritz 2017)",
    "conformal": "conformalized MCF (Kazhdan, Solomon, Ben-Chen 2012)",
    "intrinsic-delaunay": "intrinsic Delaunay operators (Sharp, Crane 2020)",
    "kll": "KLL's velocity law (Kovacs, Li, Lubich 2019)",
}
"""Tangential strategies -> description (:attr:`Scheme.tangential`): how a scheme
moves its vertices along the surface, the grouping of the findings' comparison
(:mod:`mcfbench.studies.matrix.tangential`). DDFV's are the values of its
``tangential`` option (:data:`ddfv.variants.VARIANTS`)."""


@dataclass(frozen=True)
class Scheme:
    """One scheme of the benchmark.

    Attributes
    ----------
    name : str
        Registry key, used in file names and on the command line.
    label : str
        Name in tables, legends and the report.
    flow : str
        ``"module:Class"`` of its :class:`mcfbench.running.flow.SchemeFlow` class.
    options : dict
        Keyword options of the class that make up this entry.
    style : dict
        Matplotlib line style (``color``, ``marker``, ``linestyle``).
    description : str
        One sentence for the report and ``--help``.
    family : str
        ``"ddfv"`` (the paper's scheme and its variants) or ``"vertex"``: the
        kind of its cost model (:mod:`mcfbench.running.cost`) and, in the
        figures' report, the runs compared with the paper's.
    extra_points : bool
        Its state has points besides the mesh vertices (DDFV's T-vertices, one
        per triangle): its frames carry them as ``extra_points``
        (:meth:`mcfbench.running.flow.SchemeFlow.frame`, :mod:`mcfbench.storage.frames`),
        its flow class takes their positions as ``T0`` and their placement rule as
        ``t_init``, and the T monitor applies. What the harness and the presentation
        ask of a scheme instead of its family's name.
    matrix : str
        The kind of its linear system, a key of :data:`MATRICES`:
        ``"nonsymmetric"`` or ``"scaled-spd"`` (checked on a bumpy sphere by
        ``tests/mcfbench/running/test_schemes.py``). :attr:`suited_solver` says which
        solver suits it.
    robust_solver : str
        The shared solver's method that continues a run that ended with a
        ``solver_*`` status from its last accepted state, to tell the solver's
        failure from the scheme's (the matrix study; :func:`mcfbench.running.run.run`'s
        ``robust``): :data:`mcfbench.running.solver.ROBUST`, spelled out so that
        the presentation layer reads the registry without importing the solver.
    integrator : str
        The time integrator its runs use unless told otherwise
        (:data:`mcfbench.running.integrators.INTEGRATORS`; ``"euler"`` for
        every registry entry, another for a name ``<name>@<integrator>``).
    tangential : str
        Its tangential strategy, a key of :data:`TANGENTIAL` (DDFV: its
        ``tangential`` option, ``"none"`` without one).
    integrates_itself : bool
        Its flow class steps itself in time (its ``integrates_itself``, e.g.
        :mod:`baselines.bgn_bdf`): no ``<name>@<integrator>`` of it
        (:func:`get_scheme`), said here so that a name resolves without importing
        the flow.
    """

    name: str
    label: str
    flow: str
    options: dict = field(default_factory=dict)
    style: dict = field(default_factory=dict)
    description: str = ""
    family: str = "vertex"
    extra_points: bool = False
    matrix: str = "nonsymmetric"
    robust_solver: str = "jacobi-direct"
    integrator: str = "euler"
    tangential: str = "none"
    integrates_itself: bool = False

    def __post_init__(self):
        if self.matrix not in MATRICES:
            raise ValueError(f"scheme {self.name!r}: unknown matrix kind {self.matrix!r}; "
                             f"choose one of {', '.join(MATRICES)}")
        if self.tangential not in TANGENTIAL:
            raise ValueError(f"scheme {self.name!r}: unknown tangential strategy "
                             f"{self.tangential!r}; choose one of {', '.join(TANGENTIAL)}")

    @property
    def suited_solver(self):
        """Which solver suits the scheme's matrix, one sentence (:data:`MATRICES`)."""
        return MATRICES[self.matrix]

    @property
    def flow_class(self):
        module, _, cls = self.flow.partition(":")
        return getattr(importlib.import_module(module), cls)

    def make(self, vertices, faces, tau, *, threads=1, **options):
        """The flow of ``(vertices, faces)`` with time step ``tau``.

        ``options`` override the entry's own. ``threads`` goes to a flow
        class that takes it (DDFV's per-element passes); the others run on
        one thread (their linear solves take the solver's threads).
        """
        cls = self.flow_class
        if "threads" in inspect.signature(cls).parameters:
            options = {**options, "threads": threads}
        return cls(vertices, faces, tau, **{**self.options, **options})


def _ddfv(variant, label, color, marker, linestyle, description):
    """The chord length of the dual curves makes the DDFV matrix a row scaling of a
    symmetric one (the paper's broken line does not: measured, 1e-2 off); the
    redistribution's drift (R7) weights each F-row's fluxes on its own, which does not."""
    name = "ddfv" if variant == "paper" else f"ddfv-{variant}"
    from ddfv.variants import variant_options

    options = variant_options(variant)
    return Scheme(name, label, "ddfv.flow:Flow", options,
                  {"color": color, "marker": marker, "linestyle": linestyle},
                  description, family="ddfv", extra_points=True,
                  matrix="scaled-spd" if "chord" in variant and "redistribute" not in variant
                  else "nonsymmetric", tangential=options.get("tangential", "none"))


SCHEMES = {s.name: s for s in (
    _ddfv("paper", "DDFV", "C0", "o", "-",
          "the paper's DDFV scheme: broken-line |gamma| (2.5), no tangential correction"),
    _ddfv("chord", "DDFV, chord |gamma|", "C1", "s", "--",
          "DDFV with the chord of each dual curve as |gamma|"),
    _ddfv("eliminate", "DDFV, elimination (3.6)", "C2", "^", "-.",
          "DDFV with the tangential velocity eliminated (3.6)"),
    _ddfv("chord-eliminate", "DDFV, chord + elimination", "C4", "D", ":",
          "DDFV with chord |gamma| and the elimination (3.6)"),
    _ddfv("redistribute", "DDFV, redistribution", "C8", "X", "-",
          "DDFV with the area-oriented tangential redistribution of the journal version, "
          "semi-implicit (the advection grad psi . grad X in the matrix, Peclet limit 0.1)"),
    _ddfv("chord-redistribute", "DDFV, chord + redistribution", "C9", "h", "--",
          "DDFV with chord |gamma| and the area-oriented tangential redistribution, "
          "semi-implicit"),
    _ddfv("chord-carried", "DDFV, chord, T carried", "darkgreen", "p", ":",
          "DDFV with chord |gamma| and every T-vertex carried by its triangle"),
    _ddfv("chord-redistribute-carried", "DDFV, chord + redistribution, T carried", "k", "*",
          "-.", "DDFV with chord |gamma|, semi-implicit redistribution of the F-vertices "
          "and every T-vertex carried by its triangle"),
    _ddfv("chord-bgn-carried", "DDFV, chord + BGN tangential, T carried", "indigo", "8", "--",
          "DDFV with chord |gamma|, the F-vertices' tangential motion BGN's (least Dirichlet "
          "energy of the new F-mesh at the scheme's normal displacement) and every T-vertex "
          "carried by its triangle"),
    _ddfv("chord-mdr-carried", "DDFV, chord + MDR tangential, T carried", "darkcyan", "x", "-.",
          "DDFV with chord |gamma|, the F-vertices' tangential motion MDR's (least Dirichlet "
          "energy of the displacement at the scheme's normal displacement) and every T-vertex "
          "carried by its triangle"),
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
    Scheme("cmcf", "conformalized MCF", "baselines.cmcf:CMCFFlow", {"mass": "barycentric"},
           {"color": "C6", "marker": ">", "linestyle": "-."},
           "conformalized mean curvature flow (Kazhdan, Solomon, Ben-Chen 2012): initial "
           "stiffness kept, mass rebuilt, no rescaling", matrix="scaled-spd",
           tangential="conformal"),
    Scheme("bgn", "BGN", "baselines.bgn:BGNFlow", {"scaling": "mass"},
           {"color": "C7", "marker": "P", "linestyle": ":"},
           "Barrett, Garcke, Nuernberg (2008): mass-lumped vertex normals, tangential "
           "motion that equidistributes the mesh", matrix="scaled-spd", tangential="bgn"),
    *(Scheme(f"bgn-bdf{k}", f"BGN/BDF{k}", "baselines.bgn_bdf:BGNBDFFlow",
             {"order": k, "scaling": "mass"},
             {"color": "C7", "marker": marker, "linestyle": "-."},
             f"BGN with BDF{k} in time as Jiang, Su and Zhang (2024) build it: the normals "
             f"and inner products on a predictor surface from BGN/BDF1..{k - 1} solves, "
             f"{k} solves a step", matrix="scaled-spd", tangential="bgn",
             integrates_itself=True)
      for k, marker in ((2, "1"), (3, "2"))),
    Scheme("mdr", "MDR", "baselines.mdr:MDRFlow", {"scaling": "mass"},
           {"color": "tab:cyan", "marker": "d", "linestyle": "-"},
           "minimal deformation rate (Hu, Li 2022): the velocity of least int |grad v|^2 with "
           "normal part -H, the multiplier eliminated into BGN's system with unit normals",
           matrix="scaled-spd", tangential="mdr"),
    Scheme("deturck", "DeTurck", "baselines.deturck:DeTurckFlow", {"alpha": 0.1},
           {"color": "tab:brown", "marker": "H", "linestyle": "--"},
           "the DeTurck trick (Elliott, Fritz 2017): reparametrised by the harmonic map heat "
           "flow onto the initial mesh with time scale 1/alpha, the advection implicit",
           matrix="nonsymmetric", tangential="deturck"),
    Scheme("kll", "KLL", "baselines.kll:KLLFlow", {},
           {"color": "tab:purple", "marker": "*", "linestyle": "-"},
           "Kovacs, Li, Lubich (2019): normal and mean curvature evolved by Huisken's "
           "equations, velocity -H nu, P1 elements (the proof needs degree >= 2), the "
           "velocity law linearised at the extrapolated state", matrix="nonsymmetric",
           tangential="kll"),
)}
"""Scheme name -> :class:`Scheme`."""


def split_name(name):
    """``(registry name, integrator)`` of a scheme name: ``"cotan@bdf2"`` ->
    ``("cotan", "bdf2")``, ``"cotan"`` -> ``("cotan", "euler")``."""
    base, _, integrator = name.partition("@")
    return base, integrator or "euler"


def joined_name(base, integrator):
    """The scheme name of ``base`` stepped by ``integrator`` (:func:`split_name`'s
    inverse): ``base`` itself for Euler, else ``base@integrator``."""
    return base if integrator == "euler" else f"{base}@{integrator}"


def get_scheme(name, registry=None):
    """The registry entry ``name``, or ``<name>@<integrator>``: that entry stepped by
    another integrator (its label says which; hollow markers).

    Parameters
    ----------
    name : str
    registry : dict, optional
        Name -> :class:`Scheme` (default :data:`SCHEMES`).

    Raises
    ------
    ValueError
        Unknown name or integrator, listing the known ones.
    """
    registry = SCHEMES if registry is None else registry
    base, integrator = split_name(name)
    if base not in registry:
        raise ValueError(f"unknown scheme {name!r}; choose one of "
                         f"{', '.join(registry)} (or NAME@INTEGRATOR)")
    entry = registry[base]
    if name == base:
        return entry
    if integrator not in INTEGRATORS:
        raise ValueError(f"unknown integrator {integrator!r} in scheme {name!r}; choose one "
                         f"of {', '.join(INTEGRATORS)}")
    if entry.integrates_itself:
        raise ValueError(f"scheme {base!r} integrates in time itself: no {name!r}")
    return replace(entry, name=name, integrator=integrator,
                   label=f"{entry.label}, {INTEGRATORS[integrator].label}",
                   style={**entry.style, "markerfacecolor": "none"})


def find_scheme(name, registry=None):
    """:func:`get_scheme`, or None for a name it does not know."""
    try:
        return get_scheme(name, registry)
    except ValueError:
        return None


def scheme_label(name):
    """The label of ``name`` in tables and legends (the name itself when unknown)."""
    entry = find_scheme(name)
    return name if entry is None else entry.label
