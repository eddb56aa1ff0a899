# Thin rule script: the logic is parksteer.figures.assist_study.make_assist_study.
from parksteer.figures.assist_study import make_assist_study
from parksteer.progress import note
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_assist_study(snakemake.input.parameters, snakemake.output.svg, snakemake.output.csv, snakemake.output.json,
                      snakemake.params.target, progress=note)
