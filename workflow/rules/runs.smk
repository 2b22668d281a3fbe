# The run store (mcfbench.storage.run_store): every run of every study is a spec,
# one record and one frames file under results/runs/{problem}/{scheme}/level{k}/,
# named by the spec's key. A run two studies ask for is computed once.
#
# One job per batch (mcfbench.running.batching.batches, made from the specs of
# every study while Snakemake reads the workflow: RUNS, mcfbench.pipeline.RunStore):
# the specs of one problem asked for by the same studies, cheap series gathered
# until their estimated cost reaches about 60 CPU s, a heavy series alone, the
# costliest batches first. A batch job's output is its manifest,
# results/runs/batches/<name>.json (the records cannot be outputs: Snakemake deletes
# a job's outputs before it runs it); its params are its specs with their code
# digests (mcfbench.running.identity). The job reads every spec whose record the
# store holds with the same key and code digest and computes the others
# (mcfbench.running.batch.run_batch): a batch reruns when one of its specs or
# digests changes, and only the runs whose spec or code changed are computed.
# The studies' views take the manifests of their specs as inputs.

from mcfbench.pipeline import batch_resources, run_studies
from mcfbench.storage.run_store import manifest_path

# every study's specs but those whose rule file makes its own batches (the gallery's,
# one per mesh file: mcfbench.pipeline.run_studies)
RUNS = RunStore(PLANS, run_studies())


for _batch in RUNS.batches:
    _mem_mb, _runtime = batch_resources(_batch)

    rule:
        name:
            f"runs_{_batch.name}"
        input:
            kernels=ancient(KERNELS),
        output:
            manifest_path(_batch.name),
        log:
            f"results/logs/runs/{_batch.name}.log",
        benchmark:
            f"results/benchmarks/runs/{_batch.name}.tsv"
        # the costliest batches first (estimated CPU s): long jobs start early and
        # the two cores stay busy
        priority: round(_batch.seconds)
        conda:
            "../envs/ddfv.yaml"
        threads: max(s.threads for s in _batch.specs)
        resources:
            mem_mb=_mem_mb,
            runtime=_runtime,
        params:
            runs=RUNS.entries(_batch.specs),
        script:
            "../scripts/run_batch.py"
