"""Time convergence of one DDFV scheme on one mesh: a JSON record.

Called by rule ``beyond_time`` (workflow/rules/beyond.smk) with the settings
of ``time_settings`` there. Runs :func:`ddfv.convergence.time_convergence`
(tau halved repeatedly on a fixed icosphere, distance at ``t_final`` to a
reference with ``min(taus) / reference_factor``) and writes its rows with
the settings and provenance. A reference run that breaks down does not fail
the job: the record has ``status = "reference_failed"``, the message and no
rows; runs of single time steps that break down are rows with their status.
"""

import os
import sys

# Timed jobs run single-threaded (see run_scheme.py)
BLAS_PINNED_BEFORE_NUMPY = "numpy" not in sys.modules
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import time  # noqa: E402

from run_records import setup_logging, write_json_atomic  # noqa: E402  (first: sys.path)

from ddfv.convergence import time_convergence  # noqa: E402
from ddfv.provenance import provenance  # noqa: E402

# keys of a time record besides the rows (checked by beyond_tables.py)
FIELDS = ("study", "scheme", "module", "options", "variant", "level", "taus",
          "reference_factor", "reference_tau", "t_final", "rtol", "status", "message",
          "rows", "wall_seconds", "provenance")


def main(settings, output, log_file):
    log = setup_logging(log_file)
    if settings["module"] != "ddfv.sphere":
        raise ValueError(f"the time study runs DDFV schemes only, not {settings['module']}")
    options = dict(settings["options"])
    taus, factor = settings["taus"], settings["reference_factor"]
    log.info("%s level %d: time_convergence(taus=%s, reference_factor=%d, t_final=%g, "
             "rtol=%g, **%s)", settings["scheme"], settings["level"], taus, factor,
             settings["t_final"], settings["rtol"], options)
    wall = time.perf_counter()
    try:
        table = time_convergence(settings["level"], taus, reference_factor=factor,
                                 t_final=settings["t_final"], rtol=settings["rtol"],
                                 **options)
        rows, status, message = table.to_dict("records"), "ok", ""
    except RuntimeError as err:  # the reference run broke down
        rows, status, message = [], "reference_failed", str(err)
    wall = time.perf_counter() - wall
    record = {"study": "time", "scheme": settings["scheme"], "module": settings["module"],
              "options": options, "variant": options.get("variant", "paper"),
              "level": settings["level"], "taus": taus, "reference_factor": factor,
              "reference_tau": min(taus) / factor, "t_final": settings["t_final"],
              "rtol": settings["rtol"], "status": status, "message": message,
              "rows": rows, "wall_seconds": wall, "provenance": provenance(settings)}
    record["provenance"]["blas_pinned_before_numpy"] = BLAS_PINNED_BEFORE_NUMPY
    write_json_atomic(output, record)
    log.info("%s: %s in %.1f s -> %s", settings["scheme"], status, wall, output)
    if status != "ok":
        log.warning("%s", message)
    for row in rows:
        log.info("tau %-10g error %.4e eoc %.3f %s", row["tau"], row["error"], row["eoc"],
                 row["status"])


if __name__ == "__main__":
    main(snakemake.params.settings, snakemake.output[0], snakemake.log[0])  # noqa: F821
