# Thin rule script: the logic is parksteer.experiments.variations.run_case, once per case of the job (run_batch).
from parksteer.experiments.benchmark import run_batch
from parksteer.experiments.variations import VariationDesign, run_case
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_batch(run_case, snakemake.input.parameters,
              VariationDesign.from_config(snakemake.params.design, snakemake.params.benchmark),
              snakemake.params.cases, snakemake.output[0])
