# Thin rule script: the logic is parksteer.sweep.run.run_point.
from parksteer.rules import rule_log
from parksteer.sweep.run import run_point

with rule_log(snakemake):
    run_point(snakemake.params.spec, snakemake.input.parameters, snakemake.output.point)
