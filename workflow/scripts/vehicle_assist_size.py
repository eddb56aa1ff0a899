# Thin rule script: the assist sizing study of a vehicle (parksteer.sweep.assist_sizing), its table and figures.
from pathlib import Path

from parksteer.figures.assist import write_sizing_files
from parksteer.rules import rule_log
from parksteer.sweep.assist_sizing import size_assist
from parksteer.vehicle import load_vehicle

with rule_log(snakemake):
    params = load_vehicle(snakemake.input.vehicle, snakemake.input.parameters)
    study = size_assist(params, params.case_names[0], float(snakemake.params.target),
                        tuple(float(s) for s in snakemake.params.speeds))
    write_sizing_files(study, Path(snakemake.input.vehicle).stem, snakemake.output.csv, snakemake.output.torque,
                       snakemake.output.force)
