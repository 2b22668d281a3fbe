"""A run's code identity: what of the code decides the numbers of one run.

:func:`run_identity` is what the run store keys a record's code by and what
Snakemake's params carry for a run's job. Interim: the whole-package hashes of
:func:`mcfbench.storage.provenance.code_hash` (every run shares them); the import
closure of the scheme, the problem and the harness's stepping code replaces it.
"""

from mcfbench.storage.provenance import code_hash, config_hash


def run_identity(scheme, problem):
    """The code identity of a run of ``scheme`` (a registry name, ``NAME@INTEGRATOR``
    included) on ``problem`` (a registry name): a JSON-serialisable dict."""
    return {"packages": code_hash()}


def identity_digest(identity):
    """Short SHA-256 (16 hex digits) of a :func:`run_identity`."""
    return config_hash(identity)
