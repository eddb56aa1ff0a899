# Thin rule script: the logic is parksteer.figures.baseline.gather_baseline_figure (the cars of the
# diag_baseline_batch jobs scored and drawn).
from parksteer.figures.baseline import gather_baseline_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    gather_baseline_figure(list(snakemake.input.cars), snakemake.output.svg, snakemake.output.csv,
                           snakemake.output.json)
