# Thin rule script: the logic is parksteer.figures.diagnosis_benchmarks.make_benchmark_figure.
from parksteer.figures.diagnosis_benchmarks import make_benchmark_figure
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import BenchmarkDesign

with rule_log(snakemake):
    make_benchmark_figure(list(snakemake.params.truths), list(snakemake.params.diagnoses), snakemake.output.svg,
                          snakemake.output.csv, snakemake.output.json,
                          BenchmarkDesign.from_config(snakemake.params.design))
