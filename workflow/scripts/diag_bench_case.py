# Thin rule script: the logic is parksteer.diagnose.benchmark.run_case.
from pathlib import Path

from parksteer.diagnose.benchmark import run_case
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import BenchmarkDesign

with rule_log(snakemake):
    run_case(snakemake.input.parameters, BenchmarkDesign.from_config(snakemake.params.design),
             snakemake.wildcards.name, Path(snakemake.output.files[0]).parent, snakemake.output.truth,
             snakemake.output.diagnosis)
