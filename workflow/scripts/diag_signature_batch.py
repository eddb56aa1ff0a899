# Thin rule script: the logic is parksteer.figures.signature.run_case, once per case of the job (run_batch).
from parksteer.experiments.benchmark import run_batch
from parksteer.experiments.outoflibrary import design_from_config
from parksteer.figures.signature import run_case
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_batch(run_case, snakemake.input.parameters, design_from_config(snakemake.params.design),
              snakemake.params.cases, snakemake.output[0])
