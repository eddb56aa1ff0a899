# Thin rule script: the logic is parksteer.diagnose.variations.run_case.
from pathlib import Path

from parksteer.diagnose.variations import VariationDesign, run_case
from parksteer.rules import rule_log

with rule_log(snakemake):
    Path(snakemake.output.files).mkdir(parents=True, exist_ok=True)
    run_case(snakemake.input.parameters, VariationDesign.from_config(snakemake.params.design, snakemake.params.benchmark),
             snakemake.wildcards.name, snakemake.output.files, snakemake.output.truth, snakemake.output.diagnosis)
