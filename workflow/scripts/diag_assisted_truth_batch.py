# Thin rule script: the logic is parksteer.experiments.assisted_truth.run_batch (via
# parksteer.figures.assisted_truth.run_assisted_truth_batch), once for the cases of the job.
from parksteer.figures.assisted_truth import run_assisted_truth_batch
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_assisted_truth_batch(snakemake.input.parameters, snakemake.input.vehicle, snakemake.params.design,
                             list(snakemake.params.cases), snakemake.output[0])
