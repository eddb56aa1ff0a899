# Thin rule script: the logic is parksteer.figures.diagnose.make_compare_figure.
from parksteer.figures.diagnose import make_compare_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_compare_figure(snakemake.input.parameters, list(snakemake.input.files), snakemake.output.svg,
                        snakemake.output.csv, snakemake.output.json)
