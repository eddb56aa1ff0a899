# Thin rule script: the logic is parksteer.diagnose.variations.run_case, once per case of the job.
from pathlib import Path

from parksteer.diagnose.variations import VariationDesign, run_case
from parksteer.rules import rule_log

with rule_log(snakemake):
    design = VariationDesign.from_config(snakemake.params.design, snakemake.params.benchmark)
    out = Path(snakemake.output[0])
    for name in snakemake.params.cases:
        (out / name).mkdir(parents=True, exist_ok=True)
        run_case(snakemake.input.parameters, design, name, out / name, out / f"{name}.truth.json",
                 out / f"{name}.diagnosis.json")
