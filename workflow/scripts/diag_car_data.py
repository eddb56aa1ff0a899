# Thin rule script: the logic is parksteer.synthetic.datasets.write_car_dataset.
from parksteer.synthetic.datasets import write_car_dataset
from parksteer.rules import rule_log

with rule_log(snakemake):
    write_car_dataset(snakemake.input.parameters, list(snakemake.output.files), snakemake.output.truth)
