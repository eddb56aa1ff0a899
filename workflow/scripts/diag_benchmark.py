# Thin rule script: the logic is parksteer.diagnose.benchmark.make_benchmark_figure.
from parksteer.diagnose.benchmark import make_benchmark_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_benchmark_figure(list(snakemake.input.truths), list(snakemake.input.diagnoses), snakemake.output.svg,
                          snakemake.output.csv, snakemake.output.json)
