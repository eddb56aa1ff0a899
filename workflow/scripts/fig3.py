# Thin rule script: the logic is parksteer.figures.rig.make_fig3.
from parksteer.figures.rig import make_fig3
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_fig3(snakemake.input.parameters, snakemake.output.svg, snakemake.output.csv, snakemake.output.json)
