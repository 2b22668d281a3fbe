"""Named variants of the DDFV scheme (ddfv/variants.py) and their registry entries."""

import pytest

from ddfv import Flow
from ddfv.variants import VARIANTS, variant_options
from mcfbench.geometry.spheres import icosphere
from mcfbench.running.schemes import SCHEMES


def test_variants_are_options_of_the_flow():
    V, F = icosphere(1)
    expected = {"paper": ("broken", "none", "scheme"), "chord": ("chord", "none", "scheme"),
                "eliminate": ("broken", "eliminate", "scheme"),
                "chord-eliminate": ("chord", "eliminate", "scheme"),
                "redistribute": ("broken", "redistribute", "scheme"),
                "chord-redistribute": ("chord", "redistribute", "scheme"),
                "chord-carried": ("chord", "none", "carried"),
                "chord-redistribute-carried": ("chord", "redistribute", "carried"),
                "chord-bgn-carried": ("chord", "bgn", "carried"),
                "chord-mdr-carried": ("chord", "mdr", "carried")}
    assert set(VARIANTS) == set(expected)
    for name, (dual_length, tangential, t_motion) in expected.items():
        flow = Flow(V, F, 0.01, **variant_options(name))
        assert (flow.dual_length, flow.tangential, flow.t_motion) == \
            (dual_length, tangential, t_motion)


def test_every_variant_is_a_registered_scheme():
    for name in VARIANTS:
        entry = SCHEMES["ddfv" if name == "paper" else f"ddfv-{name}"]
        assert entry.options == variant_options(name) and entry.family == "ddfv" and entry.extra_points


def test_options_are_copies():
    variant_options("chord")["dual_length"] = "broken"
    assert VARIANTS["chord"]["dual_length"] == "chord"


def test_unknown_variant_is_named():
    with pytest.raises(ValueError, match="unknown variant 'fast'; choose one of paper, chord"):
        variant_options("fast")
