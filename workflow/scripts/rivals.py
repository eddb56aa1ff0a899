# Thin rule script: the logic is parksteer.figures.rivals.make_rivals.
from parksteer.figures.rivals import make_rivals
from parksteer.progress import note
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_rivals(snakemake.input.parameters, snakemake.output.svg, snakemake.output.csv, snakemake.output.json,
                rivals=snakemake.params.rivals, progress=note)
