# Thin rule script: the logic is parksteer.figures.diagnosis_benchmarks.make_outclass_figure.
from parksteer.figures.diagnosis_benchmarks import make_outclass_figure
from parksteer.rules import rule_log
from parksteer.synthetic.outclass import OutclassDesign

with rule_log(snakemake):
    make_outclass_figure(list(snakemake.params.truths), list(snakemake.params.diagnoses), snakemake.output.svg,
                         snakemake.output.csv, snakemake.output.json,
                         OutclassDesign.from_config(snakemake.params.design, snakemake.params.benchmark))
