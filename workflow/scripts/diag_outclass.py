# Thin rule script: the logic is parksteer.figures.diagnose.make_outclass_figure.
from parksteer.figures.diagnose import make_outclass_figure
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import OutclassDesign

with rule_log(snakemake):
    make_outclass_figure(list(snakemake.params.truths), list(snakemake.params.diagnoses), snakemake.output.svg,
                         snakemake.output.csv, snakemake.output.json,
                         OutclassDesign.from_config(snakemake.params.design, snakemake.params.benchmark))
