# Thin rule script: the logic is parksteer.experiments.peers.run_peer_batch, once per job of cases.
from parksteer.experiments.peers import run_peer_batch, tuning_design
from parksteer.experiments.variations import VariationDesign
from parksteer.rules import rule_log

with rule_log(snakemake):
    design = VariationDesign.from_config(snakemake.params.design)
    run_peer_batch(snakemake.input.parameters, list(snakemake.params.jobs), snakemake.output[0],
                   tuning_design(design, snakemake.params.tuning_seed))
