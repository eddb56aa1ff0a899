# Thin rule script: the logic is parksteer.experiments.baseline.run_car (via
# parksteer.figures.baseline.run_baseline_car), once for the job's car.
from parksteer.figures.baseline import run_baseline_car
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_baseline_car(snakemake.input.parameters, snakemake.input.vehicle, snakemake.params.design,
                     snakemake.wildcards.car, snakemake.output[0])
