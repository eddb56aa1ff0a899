# Thin rule script: the vehicle study's diagnosis, its records taken in as `parksteer diagnose --vehicle` takes them
# (parksteer.diagnose.intake), its JSON, figure, report and HTML page written as the command writes them
# (parksteer.commands.diagnosis_files).
import json
from pathlib import Path

from parksteer.commands.diagnosis_files import write_diagnosis
from parksteer.diagnose.intake import Request, car_parameters, intake
from parksteer.measure.importers import channel_map_from_options
from parksteer.rules import rule_log


def measurement_files(items):
    """The rule's measurement inputs, a folder (the synthetic set) listed as its files."""
    items = [items] if isinstance(items, str) else list(items)
    out = []
    for item in items:
        path = Path(item)
        out += sorted(str(p) for p in path.iterdir() if p.suffix == ".csv") if path.is_dir() else [item]
    return out


with rule_log(snakemake):
    options = snakemake.params.options
    vehicle = snakemake.input.vehicle
    car = car_parameters(snakemake.input.parameters, vehicle)
    taken = intake(Request(measurement_files(snakemake.input.files), car, vehicle=vehicle, case=options["case"],
                           surface=options["surface"], channel_map=channel_map_from_options(None, options["map_file"]),
                           jobs=None))
    diagnosis = taken.diagnose(quiet=False)
    result = write_diagnosis(diagnosis, taken, plot=snakemake.output.svg, report=snakemake.output.md,
                             html=snakemake.output.html)
    with open(snakemake.output.json, "w", encoding="utf-8") as out:
        json.dump(result, out, indent=1, allow_nan=False)
        out.write("\n")
