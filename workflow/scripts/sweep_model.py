# Thin rule script: the logic is parksteer.sweep.run.derive_sweep_model.
from parksteer.rules import rule_log
from parksteer.sweep.run import derive_sweep_model

with rule_log(snakemake):
    derive_sweep_model(snakemake.params.effects, snakemake.output.manifest)
