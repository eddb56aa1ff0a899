# Thin rule script: the logic is parksteer.synthetic.datasets.write_car_dataset.
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import CarDesign, write_car_dataset

with rule_log(snakemake):
    design = CarDesign.from_config(snakemake.params.car)
    write_car_dataset(snakemake.input.parameters, design, list(snakemake.output.files), snakemake.output.truth)
