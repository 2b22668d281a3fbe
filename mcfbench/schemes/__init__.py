"""The built-in schemes, one module per family, found by the registry.

A module of this package declares ``SCHEME`` (one
:class:`mcfbench.running.scheme.Scheme`) or ``SCHEMES`` (a list), and ``ORDER``, an
integer: its place among the built-ins (:mod:`mcfbench.running.discovery`; ddfv 10,
cotan 20, cmcf 30, bgn 40, bgn_bdf 45, mdr 50, dual_mdr 55, deturck 60, kll 70; a module
without one comes last). The flow class a scheme names (``"module:Class"``, following
:class:`mcfbench.running.flow.SchemeFlow`) is imported on a run's first use, not
here. Modules import :mod:`mcfbench.running.scheme` and the schemes' packages'
declarative modules (``ddfv.variants``) at most: the registry imports every one of
them for ``--help``.

Adding a scheme is adding a file here, no other file edited; a scheme of one's own
package joins through the entry-point group ``mcfbench.schemes`` instead
(``docs/extending.md``).
"""
