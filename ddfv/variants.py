"""Named variants of the scheme, selectable by name in the API, CLI and pipeline.

A variant is a set of options of :class:`ddfv.Flow`; adding one is one
entry in :data:`VARIANTS` (and a line in ``ddfv/README.md``); the harness's
scheme registry (``mcfbench/running/schemes.py``) names each one ``ddfv-<variant>``.

``paper``
    The scheme as published: broken-line ``|gamma|`` (2.5), no tangential
    correction.
``chord``
    ``|gamma|`` replaced by the chord of the dual curve (``|v|``, ``|u|``).
``eliminate``
    The paper's scheme with the tangential-velocity elimination (3.6).
``chord-eliminate``
    Both: chord-length ``|gamma|`` and the elimination (3.6).
``redistribute``
    The paper's scheme with the area-oriented tangential redistribution of
    the journal version (:mod:`ddfv.redistribution`, (R1)-(R8)), semi-implicit:
    the F-rows carry the advection ``grad psi . grad X``; the T-vertices move
    with the scheme (before the semi-implicit form they moved with ``grad psi``
    too).
``chord-redistribute``
    Chord-length ``|gamma|`` and the redistribution.
``chord-carried``
    Chord-length ``|gamma|`` and every T-vertex carried by its triangle,
    no redistribution of the F-vertices.
``chord-redistribute-carried``
    Chord-length ``|gamma|``, the redistribution of the F-vertices, and
    every T-vertex carried by its triangle (kept at the barycentric
    coordinates of its initial, curvature-corrected position; see
    ``ddfv/README.md``).
``chord-bgn-carried``
    Chord-length ``|gamma|``, the F-vertices' normal displacement the
    scheme's and their tangential one BGN's (least Dirichlet energy of the
    new F-mesh, :mod:`ddfv.tangential_motion`), every T-vertex carried by its
    triangle.
``chord-mdr-carried``
    The same with MDR's tangential displacement (least Dirichlet energy of
    the displacement: the minimal deformation rate).

The T-vertex initialisation is a separate setting (``t_init``).
"""

VARIANTS = {
    "paper": {},
    "chord": {"dual_length": "chord"},
    "eliminate": {"tangential": "eliminate"},
    "chord-eliminate": {"dual_length": "chord", "tangential": "eliminate"},
    "redistribute": {"tangential": "redistribute"},
    "chord-redistribute": {"dual_length": "chord", "tangential": "redistribute"},
    "chord-carried": {"dual_length": "chord", "t_motion": "carried"},
    "chord-redistribute-carried": {"dual_length": "chord", "tangential": "redistribute",
                                   "t_motion": "carried"},
    "chord-bgn-carried": {"dual_length": "chord", "tangential": "bgn", "t_motion": "carried"},
    "chord-mdr-carried": {"dual_length": "chord", "tangential": "mdr", "t_motion": "carried"},
}


def variant_options(name):
    """Options of :class:`ddfv.Flow` that make up variant ``name``.

    Raises
    ------
    ValueError
        Unknown variant, naming the known ones.
    """
    try:
        return dict(VARIANTS[name])
    except KeyError:
        raise ValueError(f"unknown variant {name!r}; choose one of "
                         f"{', '.join(VARIANTS)}") from None
