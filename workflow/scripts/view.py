"""A study's view (any rule whose params name it: ``view``, a module of
``mcfbench.studies`` with ``view(params, outputs)``): the one adapter a new study's
rules need (docs/extending.md, "Adding a study")."""

import importlib
import logging

sm = snakemake  # noqa: F821
logging.basicConfig(filename=sm.log[0], level=logging.INFO, force=True)
params = dict(sm.params.items())
importlib.import_module(f"mcfbench.studies.{params.pop('view')}").view(params, list(sm.output))
