# Thin rule script: the vehicle study's comparison (parksteer.diagnose.compare.compare_files), its records taken in
# as `parksteer compare --vehicle` takes them (parksteer.diagnose.intake), its JSON and figure kept as the outputs.
import json

from parksteer.diagnose.compare import compare_files
from parksteer.diagnose.intake import vehicle_study
from parksteer.figures.diagnose import compare_figure
from parksteer.rules import rule_log


with rule_log(snakemake):
    taken = vehicle_study(snakemake.input.files, snakemake.input.parameters, snakemake.input.vehicle,
                          snakemake.params.options, command="compare")
    result = compare_files(taken.files, taken.params, taken.effects)
    compare_figure(result, snakemake.output.svg)
    with open(snakemake.output.json, "w", encoding="utf-8") as out:
        json.dump(result.as_dict(), out, indent=1, allow_nan=False)
        out.write("\n")
