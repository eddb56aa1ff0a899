# Thin rule script: the logic is parksteer.experiments.assisted_benchmark.run_batch (via
# parksteer.figures.assisted.run_assisted_batch), once for the cases of the job.
from parksteer.figures.assisted import run_assisted_batch
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_assisted_batch(snakemake.input.parameters, snakemake.input.vehicle, list(snakemake.params.cases),
                       snakemake.output[0])
