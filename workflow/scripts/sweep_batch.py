# Thin rule script: the logic is parksteer.sweep.run.run_batch.
from parksteer.rules import rule_log
from parksteer.sweep.run import run_batch

with rule_log(snakemake):
    run_batch(snakemake.params.spec, snakemake.input.parameters, snakemake.output.batch)
