# Thin rule script: the logic is parksteer.experiments.assisted_benchmark.run_batch, once for the cases of the job,
# on the vehicle file's car (its [assist]) over the parameter file. Called here rather than through
# parksteer.figures.assisted, whose plotting would import matplotlib into a job that draws nothing.
from parksteer.experiments.assisted_benchmark import run_batch
from parksteer.parameters import load_parameters
from parksteer.rules import rule_log
from parksteer.vehicle import load_vehicle

with rule_log(snakemake):
    run_batch(load_vehicle(snakemake.input.vehicle, load_parameters(snakemake.input.parameters)),
              list(snakemake.params.cases), snakemake.output[0])
