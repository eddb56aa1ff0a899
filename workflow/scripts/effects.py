# Thin rule script: the logic is parksteer.effect_table.write_effect_quantities.
from parksteer.effect_table import write_effect_quantities
from parksteer.rules import rule_log

with rule_log(snakemake):
    write_effect_quantities(snakemake.input.parameters, snakemake.output.json)
