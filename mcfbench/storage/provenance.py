"""Provenance of result files: the code (version, source hash, git commit),
the dependencies, the machine, the command and the settings.

Everything is looked up from the installed packages' own location, not
from the working directory, so a result written from anywhere identifies
the code that made it.
"""

import datetime
import functools
import hashlib
import json
import os
import platform
import socket
import subprocess
import sys
from importlib import metadata
from pathlib import Path

SOURCE_PACKAGES = ("ddfv", "baselines", "kept_factor", "mcfbench")
DISTRIBUTION = "ddfv-mcf"
BLAS_THREAD_VARIABLES = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def package_dir(name):
    """Folder of the importable package ``name`` (None if it is not importable)."""
    import importlib.util

    spec = importlib.util.find_spec(name)
    return Path(spec.origin).parent if spec is not None and spec.origin else None


@functools.cache
def source_hash(name):
    """Short SHA-256 of the Python sources of package ``name`` (paths and contents):
    what a result file's provenance names; what decides that a run is redone is
    its code identity (:mod:`mcfbench.running.identity`)."""
    digest = hashlib.sha256()
    root = package_dir(name)
    for path in sorted(root.rglob("*.py")):
        digest.update(path.relative_to(root).as_posix().encode() + b"\0")
        digest.update(path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


@functools.cache
def git_commit(path=None):
    """``(commit, dirty)`` of the git checkout holding ``path`` (default: the
    harness's own folder); ``("unknown", None)`` outside a checkout or without git.

    Asked once per process and path: the code a process runs is what it imported
    at its start, whatever is committed later, and two ``git`` processes per
    record cost a matrix job 0.1 s of wall time each under load (1 320 records;
    2026-11-26)."""
    cwd = Path(path) if path is not None else Path(__file__).resolve().parent
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=cwd, text=True,
                                capture_output=True, check=True).stdout.strip()
        status = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                                cwd=cwd, text=True, capture_output=True, check=True).stdout
        return commit, bool(status.strip())
    except (OSError, subprocess.CalledProcessError):
        return "unknown", None


@functools.cache
def dependency_versions():
    """``{distribution: version}`` of every installed dependency of the project
    (recursively, the extras included), sorted by name.

    Each distribution's metadata headers are parsed once (not the description
    that follows them: :func:`distribution_headers`), and a requirement that is not
    installed is looked up once: 0.02 s of CPU instead of 0.12 s, paid by
    every job when it writes its first record."""
    seen, missing, todo = {}, set(), [DISTRIBUTION]
    while todo:
        name = todo.pop()
        key = name.lower().replace("_", "-")
        if key in seen or key in missing:
            continue
        try:
            meta = distribution_headers(metadata.distribution(name))
        except metadata.PackageNotFoundError:
            missing.add(key)
            continue
        seen[key] = meta["Version"]
        todo += [requirement_name(r) for r in meta.get_all("Requires-Dist") or []]
    return dict(sorted(seen.items()))


def distribution_headers(dist):
    """The header fields of a distribution's core metadata (``METADATA``, or
    ``PKG-INFO``), an :class:`email.message.Message`: the part before the first
    empty line (after it comes the description, the longest part to parse)."""
    import email

    text = dist.read_text("METADATA") or dist.read_text("PKG-INFO") or ""
    return email.message_from_string(text.split("\n\n", 1)[0])


def requirement_name(requirement):
    name = requirement.split(";")[0]
    for stop in "<>=!~[ (":
        name = name.split(stop)[0]
    return name.strip()


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
        JSON-serialisable: ``created``, ``python``, ``version`` (of the
        project), ``source_hash`` per package, ``git_commit``, ``git_dirty``,
        ``packages`` (every dependency), ``command``, ``host``,
        ``platform``, ``blas_threads``, ``config``, ``config_hash``.
    """
    commit, dirty = git_commit()
    try:
        version = metadata.version(DISTRIBUTION)
    except metadata.PackageNotFoundError:
        version = None
    return {
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "python": sys.version.split()[0],
        "version": version,
        "source_hash": {name: source_hash(name) for name in SOURCE_PACKAGES
                        if package_dir(name) is not None},
        "git_commit": commit,
        "git_dirty": dirty,
        "packages": dependency_versions(),
        "command": [Path(sys.argv[0]).name, *sys.argv[1:]] if sys.argv and sys.argv[0] else [],
        "host": socket.gethostname(),
        "platform": platform.platform(),
        "blas_threads": {k: os.environ.get(k) for k in BLAS_THREAD_VARIABLES},
        "config": config,
        "config_hash": config_hash(config),
    }


def sidecar(settings, records, texts):
    """Provenance of aggregated tables: the settings, per input record its hash,
    commit, host and time, and the SHA-256 of every output text.

    Parameters
    ----------
    settings : dict
        What the tables depend on (:func:`provenance` of it).
    records : dict
        Record path -> record (:func:`mcfbench.storage.records.read_records`).
    texts : dict
        Output path -> its text.
    """
    data = provenance(settings)
    data["inputs"] = {path: {key: rec["provenance"].get(key) for key in
                             ("config_hash", "git_commit", "git_dirty", "host", "created",
                              "blas_threads")}
                      for path, rec in records.items()}
    data["outputs"] = {str(path): hashlib.sha256(text.encode()).hexdigest()
                       for path, text in texts.items()}
    return data
