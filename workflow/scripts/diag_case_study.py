# Thin rule script: the logic is parksteer.reporting.notebook.execute_notebook (the notebook does the work).
from pathlib import Path

from parksteer.reporting.notebook import execute_notebook
from parksteer.rules import rule_log

with rule_log(snakemake):
    execute_notebook(snakemake.input.notebook, snakemake.output.notebook, {
        "PARKSTEER_CASE_DATA": str(Path(snakemake.input.files[0]).parent),
        "PARKSTEER_CASE_TRUTH": snakemake.input.truth,
        "PARKSTEER_CASE_OUT": snakemake.output.json,
        "PARKSTEER_CASE_RESIDUALS": snakemake.output.residuals,
        "PARKSTEER_PARAMETERS": snakemake.input.parameters,
        "PARKSTEER_ASSISTED_RECORD": snakemake.input.assisted_record,
        "PARKSTEER_ASSISTED_VEHICLE": snakemake.input.assisted_vehicle,
    })
