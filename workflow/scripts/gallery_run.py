"""One scheme on one mesh file of the gallery (rule ``gallery_run``,
workflow/rules/gallery.smk; :func:`mcfbench.studies.gallery.job`)."""

import os

# Timed runs are single-threaded: BLAS reads these when numpy is first imported.
from mcfbench.storage.provenance import BLAS_THREAD_VARIABLES  # imports no numpy

os.environ.update(dict.fromkeys((*BLAS_THREAD_VARIABLES, "NUMBA_NUM_THREADS"), "1"))

from mcfbench.studies.gallery import job as gallery_job  # noqa: E402

sm = snakemake  # noqa: F821
gallery_job.job(sm.input.mesh, sm.params.settings["scheme"], sm.params.settings,
                sm.output.record, sm.output.frames, sm.log[0])
