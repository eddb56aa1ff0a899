# Thin rule script: the vehicle study's diagnosis, its records taken in as `parksteer diagnose --vehicle` takes them
# (parksteer.diagnose.intake), its JSON, figure, report and HTML page written as the command writes them
# (parksteer.commands.diagnosis_files).
import json

from parksteer.commands.diagnosis_files import write_diagnosis
from parksteer.diagnose.intake import vehicle_study
from parksteer.rules import rule_log


with rule_log(snakemake):
    taken = vehicle_study(snakemake.input.files, snakemake.input.parameters, snakemake.input.vehicle,
                          snakemake.params.options, jobs=None)
    diagnosis = taken.diagnose(quiet=False)
    result = write_diagnosis(diagnosis, taken, plot=snakemake.output.svg, report=snakemake.output.md,
                             html=snakemake.output.html)
    with open(snakemake.output.json, "w", encoding="utf-8") as out:
        json.dump(result, out, indent=1, allow_nan=False)
        out.write("\n")
