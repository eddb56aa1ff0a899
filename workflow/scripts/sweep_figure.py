# Thin rule script: the logic is parksteer.figures.sweep.make_sweep_figure.
from parksteer.figures.sweep import make_sweep_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_sweep_figure(snakemake.input.sweep, snakemake.input.parameters, snakemake.input.batches,
                      snakemake.output.svg, snakemake.output.csv, snakemake.output.json, full=snakemake.params.full)
