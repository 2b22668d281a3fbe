"""The paper's DDFV scheme and its variants (:data:`ddfv.variants.VARIANTS`): the
entries ``ddfv`` and ``ddfv-<variant>``, stepped by ``ddfv.flow:Flow``."""

from ddfv.variants import variant_options
from mcfbench.running.scheme import Scheme

ORDER = 10
"""First among the built-in schemes: the paper's."""


def _ddfv(variant, label, color, marker, linestyle, description):
    """The chord length of the dual curves makes the DDFV matrix a row scaling of a
    symmetric one (the paper's broken line does not: measured, 1e-2 off); the
    redistribution's drift (R7) weights each F-row's fluxes on its own, which does not."""
    name = "ddfv" if variant == "paper" else f"ddfv-{variant}"
    options = variant_options(variant)
    return Scheme(name, label, "ddfv.flow:Flow", options,
                  {"color": color, "marker": marker, "linestyle": linestyle},
                  description, family="ddfv", extra_points=True,
                  matrix="scaled-spd" if "chord" in variant and "redistribute" not in variant
                  else "nonsymmetric", tangential=options.get("tangential", "none"))


SCHEMES = [
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
]
