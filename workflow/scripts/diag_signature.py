# Thin rule script: the logic is parksteer.figures.signature.make_signature_figure.
from parksteer.experiments.outoflibrary import design_from_config
from parksteer.figures.signature import make_signature_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_signature_figure(list(snakemake.params.rows), snakemake.output.svg, snakemake.output.csv,
                          snakemake.output.json, design_from_config(snakemake.params.design))
