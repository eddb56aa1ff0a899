# Thin rule script: synthetic measurements of a vehicle (parksteer.synthetic.datasets.car_dataset on its car).
import dataclasses
from pathlib import Path

from parksteer.measure.io import write_measurement
from parksteer.rules import rule_log
from parksteer.synthetic.datasets import CarDesign, car_dataset, file_name
from parksteer.vehicle import load_vehicle

with rule_log(snakemake):
    params = load_vehicle(snakemake.input.vehicle, snakemake.input.parameters)
    runs = tuple((str(c), str(s)) for c, s in snakemake.params.runs)
    design = dataclasses.replace(CarDesign.from_config(snakemake.params.car),
                                 files=runs)
    dataset = car_dataset(params, design)
    out = Path(snakemake.output.files)
    out.mkdir(parents=True, exist_ok=True)
    for (case, surface), measurement in zip(runs, dataset.measurements):
        write_measurement(out / file_name(case, surface), measurement, params)
