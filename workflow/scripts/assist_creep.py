# Thin rule script: the logic is parksteer.figures.assist_creep.make_assist_creep.
from parksteer.figures.assist_creep import make_assist_creep
from parksteer.progress import note
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_assist_creep(snakemake.input.parameters, snakemake.output.svg, snakemake.output.csv, snakemake.output.json,
                      progress=note)
