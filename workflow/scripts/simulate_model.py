# Thin rule script: the logic is parksteer.figures.model.write_simulation.
from parksteer.figures.model import write_simulation
from parksteer.rules import rule_log

with rule_log(snakemake):
    write_simulation(snakemake.input.parameters, snakemake.wildcards.case, snakemake.wildcards.variant,
                     snakemake.params.effects, snakemake.params.surface, snakemake.output.csv)
