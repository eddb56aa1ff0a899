# Thin rule script: the logic is parksteer.figures.diagnose.make_ladder_figure.
from parksteer.figures.diagnose import make_ladder_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_ladder_figure(snakemake.input.study, snakemake.input.residuals, snakemake.output.svg,
                       snakemake.output.csv, snakemake.output.json)
