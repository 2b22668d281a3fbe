"""One scheme on one mesh file of the gallery (rule ``gallery_run``,
workflow/rules/gallery.smk; :func:`mcfbench.studies.gallery.job`)."""

import os

# Timed runs are single-threaded: BLAS reads these when numpy is first imported.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS",
             "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

from mcfbench.studies.gallery import job as gallery_job  # noqa: E402

sm = snakemake  # noqa: F821
gallery_job.job(sm.input.mesh, sm.params.settings["scheme"], sm.params.settings,
            sm.output.record, sm.output.frames, sm.log[0])
