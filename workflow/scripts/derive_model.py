# Thin rule script: the logic is parksteer.figures.model.derive_model.
from parksteer.figures.model import derive_model
from parksteer.rules import rule_log

with rule_log(snakemake):
    derive_model(snakemake.wildcards.model, snakemake.output.manifest)
