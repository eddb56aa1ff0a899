# Thin rule script: the logic is parksteer.figures.assisted.make_assisted_figure.
from parksteer.figures.assisted import make_assisted_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_assisted_figure(snakemake.input.parameters, snakemake.input.vehicle, snakemake.output.svg,
                         snakemake.output.csv, snakemake.output.json)
