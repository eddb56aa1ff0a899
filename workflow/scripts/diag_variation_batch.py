# Thin rule script: the logic is parksteer.diagnose.variations.run_case, once per case of the job (run_batch).
from parksteer.diagnose.benchmark import run_batch
from parksteer.diagnose.variations import VariationDesign, run_case
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_batch(run_case, snakemake.input.parameters,
              VariationDesign.from_config(snakemake.params.design, snakemake.params.benchmark),
              snakemake.params.cases, snakemake.output[0])
