"""Run one scheme on one sphere level and write its run record (JSON).

Called by rule ``run_scheme`` (workflow/rules/convergence.smk) through
Snakemake's ``script:`` directive; the settings come from
``params.settings`` (see ``run_settings`` in workflow/rules/common.smk).
"""

import os
import sys

# Timed jobs run single-threaded: BLAS reads these when numpy is first
# imported, so they are set before any import that could pull numpy in.
BLAS_PINNED_BEFORE_NUMPY = "numpy" not in sys.modules
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import importlib  # noqa: E402

from run_records import setup_logging, write_json_atomic  # noqa: E402  (first: sys.path)

from ddfv.provenance import provenance  # noqa: E402


def main(settings, output, log_file):
    log = setup_logging(log_file)
    module = importlib.import_module(settings["module"])
    options = settings["options"]
    log.info("%s level %d: %s.sphere_run(tau=%g, t_final=%g, rtol=%g, **%s)",
             settings["scheme"], settings["level"], settings["module"],
             settings["tau"], settings["t_final"], settings["rtol"], options)
    run = module.sphere_run(settings["level"], tau=settings["tau"],
                            t_final=settings["t_final"], radius=settings["radius"],
                            rtol=settings["rtol"], **options)
    record = {"scheme": settings["scheme"], "module": settings["module"],
              "options": options, **run.to_dict(), "t_final": settings["t_final"],
              "rtol": settings["rtol"], "provenance": provenance(settings)}
    record["provenance"]["blas_pinned_before_numpy"] = BLAS_PINNED_BEFORE_NUMPY
    write_json_atomic(output, record)
    log.info("%s level %d: status %s, L2 error %.4e, %d iterations, %.3f s wall -> %s",
             settings["scheme"], settings["level"], run.status, run.l2_error,
             run.iterations, run.wall_seconds, output)
    if run.status != "ok":
        log.warning("%s", run.message)


if __name__ == "__main__":
    main(snakemake.params.settings, snakemake.output[0], snakemake.log[0])  # noqa: F821
