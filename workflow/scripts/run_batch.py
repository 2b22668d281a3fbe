"""Rules runs_<batch>: the specs of one batch into the run store, and its manifest.

``params.runs``: per spec its dict and code digest (:class:`mcfbench.pipeline.RunStore`);
the job is :func:`mcfbench.running.batch.run_batch`: a spec whose record the store
holds with the same key and code digest is read, the others are run.
"""

from mcfbench.running.batch import run_batch
from mcfbench.storage.memory import tune_malloc

tune_malloc()  # before any flow allocates: halves the wall time of level 5

sm = snakemake  # noqa: F821
run_batch(list(sm.params.runs), str(sm.output[0]), sm.log[0])
