# Thin rule script: the vehicle study's comparison (parksteer.diagnose.compare.compare_files), its records taken in
# as `parksteer compare --vehicle` takes them (parksteer.diagnose.intake), its JSON and figure kept as the outputs.
import json
from pathlib import Path

from parksteer.diagnose.compare import compare_files
from parksteer.diagnose.intake import Request, car_parameters, intake
from parksteer.figures.diagnose import compare_figure
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
                           command="compare"))
    result = compare_files(taken.files, taken.params, taken.effects)
    compare_figure(result, snakemake.output.svg)
    with open(snakemake.output.json, "w", encoding="utf-8") as out:
        json.dump(result.as_dict(), out, indent=1, allow_nan=False)
        out.write("\n")
