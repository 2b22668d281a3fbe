"""Provenance of result files: versions, git commit, machine, settings."""

import datetime
import hashlib
import json
import os
import platform
import socket
import subprocess
import sys
from importlib import metadata
from pathlib import Path

PACKAGES = ("ddfv-mcf", "numpy", "scipy", "libigl", "pandas", "matplotlib", "snakemake")
BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def git_commit(path=None):
    """``(commit, dirty)`` of the git checkout containing ``path`` (default: cwd).

    ``("unknown", None)`` outside a checkout or without git.
    """
    try:
        cwd = Path(path or Path.cwd())
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=cwd, text=True,
                                capture_output=True, check=True).stdout.strip()
        status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                                cwd=cwd, text=True, capture_output=True, check=True).stdout
        return commit, bool(status.strip())
    except (OSError, subprocess.CalledProcessError):
        return "unknown", None


def config_hash(config):
    """Short SHA-256 of a JSON-serialisable configuration."""
    text = json.dumps(config, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def provenance(config=None):
    """Everything needed to trace a result back to its inputs.

    Parameters
    ----------
    config : dict, optional
        The settings that produced the result; stored with its hash.

    Returns
    -------
    dict
        JSON-serialisable.
    """
    versions = {}
    for name in PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    commit, dirty = git_commit()
    return {
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "python": sys.version.split()[0],
        "packages": versions,
        "git_commit": commit,
        "git_dirty": dirty,
        "host": socket.gethostname(),
        "platform": platform.platform(),
        "blas_threads": {k: os.environ.get(k) for k in BLAS_THREAD_VARIABLES},
        "config": config,
        "config_hash": config_hash(config),
    }
