# Thin rule script: the logic is parksteer.figures.lifting.make_figA3.
from parksteer.figures.lifting import make_figA3
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_figA3(snakemake.input.parameters, snakemake.output.svg, snakemake.output.csv, snakemake.output.json)
