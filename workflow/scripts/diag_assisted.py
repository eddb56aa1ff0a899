# Thin rule script: the logic is parksteer.figures.assisted.gather_assisted_figure (the rows of the
# diag_assisted_batch jobs scored and drawn).
from parksteer.figures.assisted import gather_assisted_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    gather_assisted_figure(list(snakemake.input.batches), list(snakemake.params.cases), snakemake.input.vehicle,
                           snakemake.output.svg, snakemake.output.csv, snakemake.output.json)
