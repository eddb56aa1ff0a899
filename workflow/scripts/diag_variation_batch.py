# Thin rule script: the logic is parksteer.experiments.variations.run_case, once per case of the job (run_batch);
# the peers run on each diagnosis as it is made (parksteer.experiments.peers.peers_beside).
from parksteer.experiments.benchmark import run_batch
from parksteer.experiments.peers import peers_beside
from parksteer.experiments.variations import VariationDesign, run_case
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_batch(run_case, snakemake.input.parameters,
              VariationDesign.from_config(snakemake.params.design),
              snakemake.params.cases, snakemake.output[0], on_diagnosis=peers_beside("variations"))
