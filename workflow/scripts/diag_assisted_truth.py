# Thin rule script: the logic is parksteer.figures.assisted_truth.gather_assisted_truth_figure (the rows of the
# diag_assisted_truth_batch jobs scored and drawn).
from parksteer.figures.assisted_truth import gather_assisted_truth_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    gather_assisted_truth_figure(list(snakemake.input.batches), list(snakemake.params.cases), snakemake.params.design,
                                 snakemake.input.vehicle, snakemake.output.svg, snakemake.output.csv,
                                 snakemake.output.json)
