# Thin rule script: the logic is parksteer.sweep.run.run_batch; the batch's points come from the sweep's batch
# index (parksteer.sweep.batch_index.batch_spec_from_index), at the batch size and sweep_full of workflow/rules/sweep.smk.
from parksteer.rules import rule_log
from parksteer.sweep.batch_index import batch_spec_from_index
from parksteer.sweep.expansion import DEFAULT_BATCH_SIZE
from parksteer.sweep.run import run_batch

with rule_log(snakemake):
    spec = batch_spec_from_index(
        snakemake.input.declaration, snakemake.input.parameters, bool(snakemake.config.get("sweep_full", False)),
        int(snakemake.config.get("sweep_batch_size", DEFAULT_BATCH_SIZE)), snakemake.wildcards.batch,
        snakemake.params.shared, snakemake.params.index_dir,
    )
    run_batch(spec, snakemake.input.parameters, snakemake.output.batch)
