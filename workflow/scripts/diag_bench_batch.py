# Thin rule script: the logic is parksteer.experiments.benchmark.run_case, once per case of the job (run_batch).
from parksteer.experiments.benchmark import run_batch, run_case
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import BenchmarkDesign

with rule_log(snakemake):
    run_batch(run_case, snakemake.input.parameters, BenchmarkDesign.from_config(snakemake.params.design),
              snakemake.params.cases, snakemake.output[0])
