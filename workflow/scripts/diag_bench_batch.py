# Thin rule script: the logic is parksteer.diagnose.benchmark.run_case, once per case of the job.
from pathlib import Path

from parksteer.diagnose.benchmark import run_case
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import BenchmarkDesign

with rule_log(snakemake):
    design = BenchmarkDesign.from_config(snakemake.params.design)
    out = Path(snakemake.output[0])
    for name in snakemake.params.cases:
        (out / name).mkdir(parents=True, exist_ok=True)
        run_case(snakemake.input.parameters, design, name, out / name, out / f"{name}.truth.json",
                 out / f"{name}.diagnosis.json")
