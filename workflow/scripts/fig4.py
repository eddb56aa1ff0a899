# Thin rule script: the logic is parksteer.figures.rig.make_fig4.
from parksteer.figures.rig import make_fig4
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_fig4(snakemake.input.parameters, snakemake.output.svg, snakemake.output.csv, snakemake.output.json)
