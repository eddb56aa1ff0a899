# Thin rule script: the logic is parksteer.figures.diagnosis_benchmarks.make_variations_figure.
from parksteer.experiments.variations import VariationDesign
from parksteer.figures.diagnosis_benchmarks import make_variations_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_variations_figure(list(snakemake.params.truths), list(snakemake.params.diagnoses), snakemake.output.svg,
                           snakemake.output.csv, snakemake.output.json,
                           VariationDesign.from_config(snakemake.params.design))
