"""One scheme of the benchmark: its flow class, options, label, plot style and kinds.

:class:`Scheme` is what a scheme module of :mod:`mcfbench.schemes` (or an installed
package's entry point in the group ``mcfbench.schemes``) declares; the registry
:mod:`mcfbench.running.schemes` finds them. A scheme module imports this module,
not the registry.
"""

import importlib
import inspect
from dataclasses import dataclass, field
from typing import NamedTuple

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
    "dual-mdr": "MDR's with a tangential dual multiplier, energy-stable (Gao, Li, Tang 2026)",
    "deturck": "DeTurck (Elliott, Fritz 2017)",
    "conformal": "conformalized MCF (Kazhdan, Solomon, Ben-Chen 2012)",
    "intrinsic-delaunay": "intrinsic Delaunay operators (Sharp, Crane 2020)",
    "kll": "KLL's velocity law (Kovacs, Li, Lubich 2019)",
}
"""Tangential strategies -> description (:attr:`Scheme.tangential`): how a scheme
moves its vertices along the surface, the grouping of the findings' comparison
(:mod:`mcfbench.studies.matrix.tangential`). DDFV's are the values of its
``tangential`` option (:data:`ddfv.variants.VARIANTS`)."""

MESH_STRATEGIES = {
    "remesh": "isotropic remeshing when the mesh's quality fails (Botsch, Kobbelt 2004; "
              "mcfbench.running.remeshing)",
    "surgery": "a neck pinched below half an edge is cut and both sides capped, the parts "
               "thinner than an edge re-extracted once a tip or rim is about to fold, the "
               "mesh remeshed as +remesh does; the run going on (mcfbench.running.surgery)",
}
"""Suffixes of a scheme name ``NAME[@INTEGRATOR][+STRATEGY]`` -> description: what a run
does to its mesh besides stepping it (:attr:`Scheme.mesh_strategy`, :func:`parse_name`;
the driver's hook is built by :func:`mcfbench.running.remeshing.mesh_hook`). A new
strategy is one key here and one entry of that function's table."""


class SchemeName(NamedTuple):
    """The parts of a scheme name (:func:`parse_name`)."""

    base: str
    """The registry entry's name."""
    integrator: str
    """``"euler"`` unless ``@INTEGRATOR`` says otherwise."""
    strategy: str
    """A key of :data:`MESH_STRATEGIES`, or ``"none"``."""


def parse_name(name):
    """The parts of a scheme name ``NAME[@INTEGRATOR][+STRATEGY]``: the integrator first,
    then the mesh strategy (``"cotan@bdf2+remesh"`` -> ``("cotan", "bdf2", "remesh")``;
    ``"cotan"`` -> ``("cotan", "euler", "none")``). Checks the strategy (a key of
    :data:`MESH_STRATEGIES`), not the base or integrator (the registry's).

    Raises
    ------
    ValueError
        An unknown strategy, or the suffixes in the other order.
    """
    rest, plus, strategy = name.partition("+")
    base, _, integrator = rest.partition("@")
    if plus and strategy not in MESH_STRATEGIES:
        raise ValueError(f"scheme {name!r}: unknown mesh strategy {strategy!r} (after '+'); "
                         f"choose one of {', '.join(MESH_STRATEGIES)}; the order is "
                         "NAME@INTEGRATOR+STRATEGY")
    return SchemeName(base, integrator or "euler", strategy if plus else "none")


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
        (:func:`mcfbench.running.schemes.get_scheme`), said here so that a name
        resolves without importing the flow.
    mesh_strategy : str
        What its runs do to the mesh besides stepping it: ``"none"`` for every
        registry entry, a key of :data:`MESH_STRATEGIES` for a name
        ``<name>+<strategy>``: ``"remesh"`` or ``"surgery"`` (a neck pinch cut and
        capped, the run going on: :mod:`mcfbench.running.surgery`).
    module : str
        The module that declared it (set by the registry's discovery,
        :mod:`mcfbench.running.discovery`).
    source : dict or None
        An installed package's scheme (entry point): ``distribution``, ``version``
        and ``files_sha256``, the SHA-256 of its package's files
        (:func:`mcfbench.running.discovery.package_source`): its code identity
        besides ``flow``'s module; None for the built-ins.
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
    mesh_strategy: str = "none"
    module: str = field(default="", compare=False)
    source: dict | None = field(default=None, compare=False)

    def __post_init__(self):
        base, integrator, strategy = parse_name(self.name)     # get_scheme's derived names
        at = "@" in self.name
        if not base or any(c in base for c in "/ ") or \
                (at and integrator in ("euler", "") or integrator != self.integrator) or \
                strategy != self.mesh_strategy:
            raise ValueError(f"scheme {self.name!r}: a name is a non-empty word without "
                             "'/', '@', '+' or spaces (a folder of the results; '@' joins an "
                             "integrator, '+' a mesh strategy)")
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
        class that takes it (DDFV's per-element passes; the assembly and checks of
        cotan's and BGN's classes and of their subclasses that keep their
        constructor); the others run on one thread (their linear solves take the
        solver's threads), and the driver's checks take the flow's.
        """
        cls = self.flow_class
        if "threads" in inspect.signature(cls).parameters:
            options = {**options, "threads": threads}
        return cls(vertices, faces, tau, **{**self.options, **options})
