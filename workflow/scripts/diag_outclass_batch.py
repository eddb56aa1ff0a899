# Thin rule script: the logic is parksteer.experiments.outclass.run_case, once per case of the job (run_batch).
from parksteer.experiments.benchmark import run_batch
from parksteer.experiments.outclass import run_case
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import OutclassDesign

with rule_log(snakemake):
    run_batch(run_case, snakemake.input.parameters,
              OutclassDesign.from_config(snakemake.params.design, snakemake.params.benchmark),
              snakemake.params.cases, snakemake.output[0])
