# Thin rule script: the logic is parksteer.diagnose.benchmark.run_case.
from pathlib import Path

from parksteer.diagnose.benchmark import run_case
from parksteer.rules import rule_log

with rule_log(snakemake):
    run_case(snakemake.input.parameters, snakemake.wildcards.name, Path(snakemake.output.files[0]).parent,
             snakemake.output.truth, snakemake.output.diagnosis)
