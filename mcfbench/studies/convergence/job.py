"""Table 3.1 computed in one process (:func:`sphere_table`, the command line's
``sphere-table``; the pipeline's runs are specs in the run store)."""


def sphere_table(levels, scheme="ddfv", **options):
    """Table 3.1: the problem ``sphere`` on each level, EOC and published values.

    Parameters
    ----------
    levels : sequence of int
    scheme : str
        A name of :data:`mcfbench.running.schemes.SCHEMES`.
    **options
        Passed to :func:`mcfbench.running.run.run` (``solver``, scheme options).

    Returns
    -------
    pandas.DataFrame
        One row per level: the fields of :class:`mcfbench.storage.records.RunResult`,
        ``eoc`` (3.1) against the previous level when that is one coarser,
        and the published values as ``paper_*`` with ``l2_ratio = l2_error /
        paper_l2_error``.
    """
    import pandas as pd

    from mcfbench.running.run import level_sweep
    from mcfbench.studies.convergence.tables import PUBLISHED, PUBLISHED_COLUMNS

    table = level_sweep(scheme, "sphere", levels, **options)
    table.insert(table.columns.get_loc("iterations") + 1, "eoc", table.pop("eoc_l2_error"))
    published = pd.DataFrame.from_dict(PUBLISHED, orient="index",
                                       columns=PUBLISHED_COLUMNS)
    for column in ("l2_error", "iterations", "eoc", "cpu_seconds"):
        table[f"paper_{column}"] = table["level"].map(published[column])
    table["l2_ratio"] = table["l2_error"] / table["paper_l2_error"]
    return table
