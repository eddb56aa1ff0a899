# Thin rule script: the logic is parksteer.diagnose.outclass.run_case.
from pathlib import Path

from parksteer.diagnose.outclass import run_case
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import OutclassDesign

with rule_log(snakemake):
    run_case(snakemake.input.parameters,
             OutclassDesign.from_config(snakemake.params.design, snakemake.params.benchmark),
             snakemake.wildcards.name, Path(snakemake.output.files[0]).parent, snakemake.output.truth,
             snakemake.output.diagnosis)
