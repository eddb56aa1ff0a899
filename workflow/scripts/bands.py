# Thin rule script: the logic is parksteer.figures.bands.make_bands.
from parksteer.figures.bands import make_bands
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_bands(snakemake.input.parameters, snakemake.output.svg, snakemake.output.csv, snakemake.output.json)
