# Thin rule script: the logic is parksteer.paper.write_effect_quantities.
from parksteer.paper import write_effect_quantities
from parksteer.rules import rule_log

with rule_log(snakemake):
    write_effect_quantities(snakemake.input.parameters, snakemake.output.json)
