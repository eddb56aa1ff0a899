# Thin rule script: the logic is parksteer.figures.rig.make_table1.
from parksteer.figures.rig import make_table1
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_table1(snakemake.input.parameters, snakemake.input.printed, snakemake.output.csv, snakemake.output.json)
