"""Logging of a job: to its log file (if given) and to stderr (shown by Snakemake)."""

import logging
import sys
from pathlib import Path


def setup_logging(log_file=None):
    """Log to the job's log file (if given) and to stderr (shown by Snakemake)."""
    handlers = [logging.StreamHandler(sys.stderr)]
    if log_file:
        Path(log_file).parent.mkdir(parents=True, exist_ok=True)
        handlers.insert(0, logging.FileHandler(log_file, mode="w"))
    logging.basicConfig(level=logging.INFO, handlers=handlers, force=True,
                        format="%(asctime)s %(levelname)s %(message)s")
    return logging.getLogger("pipeline")
