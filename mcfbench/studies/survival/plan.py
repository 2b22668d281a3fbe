"""The plan of the survival study: the config key ``survival`` checked (:func:`plan`) and
one run-store spec per readable raw mesh and scheme (:func:`survival_specs`).

Every scheme is run as it is and with each mesh strategy of ``strategies`` (default
``[remesh]``: issue #44 asks for every scheme with and without remeshing), the
variant ``NAME+STRATEGY`` right after ``NAME`` (:func:`paired_schemes`); the tables
show them side by side (:func:`mcfbench.studies.survival.tables.paired_markdown`).
"""

from mcfbench.studies.config import ConfigError, check_mesh_runs, listed

STRATEGIES = ("remesh",)
"""The mesh strategies every scheme of the study is also run with by default."""


def paired_schemes(schemes, strategies):
    """``schemes`` with ``NAME+STRATEGY`` after each ``NAME`` that has no strategy yet,
    for every strategy of ``strategies`` (in order; a name given twice once).

    Examples
    --------
    >>> paired_schemes(["bgn", "mdr+remesh"], ["remesh"])
    ['bgn', 'bgn+remesh', 'mdr+remesh']
    """
    out = []
    for name in schemes:
        variants = [name] if "+" in name else [name, *(f"{name}+{s}" for s in strategies)]
        out += [v for v in variants if v not in out]
    return out


def plan(section=None):
    """The config key ``survival`` checked and normalised.

    Parameters
    ----------
    section : dict, optional
        ``schemes``, ``C``, ``steps``, ``solver``, ``rtol``, ``maxiter``
        (:func:`mcfbench.studies.config.check_mesh_runs`), ``meshes`` ("all" or
        names of the raw corpus), ``strategies`` (mesh strategies of
        :data:`mcfbench.running.scheme.MESH_STRATEGIES` every scheme is also run
        with; default :data:`STRATEGIES`, ``[]`` for none, ``all`` for every one) and
        ``surgery`` (scheme names also run as ``NAME+surgery``, after the pairs: the
        continuation through the thin parts' singularities,
        :mod:`mcfbench.running.surgery`).

    Returns
    -------
    dict
        Those settings (``schemes`` with their variants, :func:`paired_schemes`),
        ``strategies`` (list) and ``meshes``: name -> ``{"file", "sha256",
        "thin_features", "kind"}`` of the chosen meshes that the intake reads (the
        refused ones name their defect in the manifest: the intake's verdict, not a
        run's), ``refused``: their names, and ``max_removed_share`` (the share of the
        area a counted ``NAME+surgery`` run's continuations may remove).

    Raises
    ------
    ConfigError
        A bad value, or a mesh name not in the corpus, naming the key.
    """
    from mcfbench.geometry.committed_meshes import RAW_DIR, raw_manifest
    from mcfbench.running.continuation import MAX_REMOVED_SHARE
    from mcfbench.running.scheme import MESH_STRATEGIES

    section = dict(section or {})
    chosen = section.pop("meshes", "all")
    strategies = listed(section.pop("strategies", list(STRATEGIES)), MESH_STRATEGIES)
    bad = [s for s in strategies if s not in MESH_STRATEGIES]
    if bad:
        raise ConfigError(f"config key 'survival.strategies': unknown mesh strategy(ies) "
                          f"{bad}; choose among {', '.join(MESH_STRATEGIES)}")
    continued = section.pop("surgery", [])
    if not isinstance(continued, list) or any("+" in str(n) for n in continued):
        raise ConfigError("config key 'survival.surgery': a list of scheme names without "
                          f"'+' (each run also as NAME+surgery), got {continued!r}")
    settings = check_mesh_runs(section, "survival")
    settings["schemes"] = paired_schemes(settings["schemes"], strategies)
    extra = check_mesh_runs({"schemes": [f"{n}+surgery" for n in continued]},
                            "survival.surgery")["schemes"]
    settings["schemes"] += [s for s in extra if s not in settings["schemes"]]
    manifest = raw_manifest()
    names = listed(chosen, manifest)
    unknown = [n for n in names if n not in manifest]
    if unknown:
        raise ConfigError(f"config key 'survival.meshes': unknown mesh(es) {unknown}; the "
                          f"raw corpus (mcfbench/data/raw_meshes) has {', '.join(manifest)}")
    read = [n for n in names if manifest[n]["intake"] == "read"]
    return {**settings, "strategies": strategies, "max_removed_share": MAX_REMOVED_SHARE,
            "meshes": {n: {"file": str(RAW_DIR / manifest[n]["file"]),
                           "sha256": manifest[n]["sha256"],
                           "thin_features": bool(manifest[n]["thin_features"]),
                           "kind": manifest[n]["kind"]} for n in read},
            "refused": [n for n in names if n not in read]}


def survival_specs(plan):
    """``{(mesh, scheme): spec}``: every scheme on every mesh of the plan, its first
    and last frames kept (:func:`mcfbench.running.batch.mesh_spec`)."""
    from mcfbench.running.batch import mesh_spec

    solver = {"method": plan["solver"], "rtol": plan["rtol"], "maxiter": plan["maxiter"]}
    return {(name, scheme): mesh_spec(scheme, mesh["file"], mesh["sha256"], tau_edge=plan["C"],
                                      steps=plan["steps"], solver=solver, frames=2)
            for name, mesh in plan["meshes"].items() for scheme in plan["schemes"]}


def run_specs(plans):
    """The specs of the study (the run store's: :class:`mcfbench.pipeline.RunStore`)."""
    return survival_specs(plans.plan("survival")).values()


def from_config(config, plans):
    """:func:`plan` of the config (:meth:`mcfbench.pipeline.Plans.plan`)."""
    return plan(config.get("survival"))
