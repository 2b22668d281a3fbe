"""The registry of schemes: name -> flow class, options, label and plot style.

One entry per scheme; the command line, the studies, the pipeline, the
tables, the figures and the report all look schemes up here, so a new
scheme is one module (a class following :class:`mcfbench.flow.Flow`) plus
one entry of :data:`SCHEMES`. The flow class is named as
``"module:Class"`` and imported on first use.

The DDFV variants are entries ``ddfv``, ``ddfv-<variant>`` with the options
of :data:`ddfv.variants.VARIANTS`.
"""

import importlib
import inspect
from dataclasses import dataclass, field


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
        ``"module:Class"`` of its :class:`mcfbench.flow.Flow` class.
    options : dict
        Keyword options of the class that make up this entry.
    style : dict
        Matplotlib line style (``color``, ``marker``, ``linestyle``).
    description : str
        One sentence for the report and ``--help``.
    family : str
        ``"ddfv"`` (F- and T-vertices; the T monitor applies) or
        ``"vertex"`` (the mesh vertices only).
    """

    name: str
    label: str
    flow: str
    options: dict = field(default_factory=dict)
    style: dict = field(default_factory=dict)
    description: str = ""
    family: str = "vertex"

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
    name = "ddfv" if variant == "paper" else f"ddfv-{variant}"
    from ddfv.variants import variant_options

    return Scheme(name, label, "ddfv.flow:Flow", variant_options(variant),
                  {"color": color, "marker": marker, "linestyle": linestyle},
                  description, family="ddfv")


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
          "DDFV with the area-oriented tangential redistribution of the journal version"),
    _ddfv("chord-redistribute", "DDFV, chord + redistribution", "C9", "h", "--",
          "DDFV with chord |gamma| and the area-oriented tangential redistribution"),
    _ddfv("chord-carried", "DDFV, chord, T carried", "C5", "p", ":",
          "DDFV with chord |gamma| and every T-vertex carried by its triangle"),
    _ddfv("chord-redistribute-carried", "DDFV, chord + redistribution, T carried", "k", "*",
          "-.", "DDFV with chord |gamma|, redistribution of the F-vertices and every "
          "T-vertex carried by its triangle"),
    Scheme("cotan", "cotangent", "baselines.cotan:CotanFlow", {"mass": "barycentric"},
           {"color": "C3", "marker": "v", "linestyle": "-"},
           "the cotangent scheme (Dziuk 1991), barycentric lumped mass"),
    Scheme("cotan-voronoi", "cotangent, Voronoi mass", "baselines.cotan:CotanFlow",
           {"mass": "voronoi"}, {"color": "C5", "marker": "<", "linestyle": "--"},
           "the cotangent scheme (Dziuk 1991), Voronoi (mixed) lumped mass (Meyer et al. 2003)"),
    Scheme("cmcf", "conformalized MCF", "baselines.cmcf:CMCFFlow", {"mass": "barycentric"},
           {"color": "C6", "marker": ">", "linestyle": "-."},
           "conformalized mean curvature flow (Kazhdan, Solomon, Ben-Chen 2012): initial "
           "stiffness kept, mass rebuilt, no rescaling"),
    Scheme("bgn", "BGN", "baselines.bgn:BGNFlow", {"scaling": "mass"},
           {"color": "C7", "marker": "P", "linestyle": ":"},
           "Barrett, Garcke, Nuernberg (2008): mass-lumped vertex normals, tangential "
           "motion that equidistributes the mesh"),
)}
"""Scheme name -> :class:`Scheme`."""


def get_scheme(name):
    """The registry entry ``name``.

    Raises
    ------
    ValueError
        Unknown name, listing the known ones.
    """
    try:
        return SCHEMES[name]
    except KeyError:
        raise ValueError(f"unknown scheme {name!r}; choose one of "
                         f"{', '.join(SCHEMES)}") from None
