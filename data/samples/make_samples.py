"""The small sample inputs under data/samples/ that the README and docs/ run their commands on, so that every
documented path (a logger's CSV with its channel map, a raw CAN log in candump and BLF, a set of car records) can
be tried on a fresh clone before any pipeline has run.

- ``car/``: three records of the paper's car with the pipeline's hidden effect (config/config.yaml ``car``: rack
  stiction, 300 N), made as rule ``diag_car_data`` makes its set (:func:`parksteer.synthetic.datasets.
  write_car_dataset`), on three of its six conditions.
- ``my_car/run1.csv`` and ``my_car.map``: a logger's export (its own channel names, the rack in millimetres, the
  angle in degrees, no case or surface stated) of the car docs/vehicles.md specifies with ``parksteer vehicle new``,
  simulated at its kerb load on the ground with a column friction of 0.5 N m hidden, with noise and quantisation.
- ``polo_kerb.log`` (candump) and ``polo_kerb.blf`` (Vector BLF): the VW Polo VI of data/vehicles/polo_vi.toml with
  its column assist, kerb load on the ground, as its powertrain CAN sends it on the shipped ``vw_mqb`` bus
  (:func:`parksteer.measure.bus.encode_frames`: driver's torque at the torsion bar, steering-wheel angle, speed 0).
- ``worn_rack.csv``: the paper's car with a rack friction peaked at the centre in a form no candidate of the
  library has (``A / (1 + (x / 12 mm)^2) tanh(beta v)``, A = :data:`WORN_PEAK_N`: a bore worn tight straight ahead),
  its base parameters moved off the file's as the benchmarks move them, driven by another hand and logged by a
  50 Hz logger with its quantisation and noise (the variation benchmark's ``rate_8pc_50Hz``): the record of the
  README's loop, where the diagnosis is ``unexplained`` until the user's effect is added.
- ``polo_baseline.csv``, ``polo_drag.csv`` and ``polo_repaired.csv``: the same Polo's kerb cycle as its bus logs it
  (torsion-bar torque, motor current, rack), its gear as built (torque constant 0.055 N m/A, motor friction
  0.03 N m) rather than as the file's data say; then later with a motor that drags (0.09 N m); then after its
  repair (0.03 N m again, another hand): the baseline-then-diagnose example of README.md and
  docs/assist_identify.md.

Made again, byte for byte, by ``python data/samples/make_samples.py`` (a script beside them, not part of the package:
it drives the command line, which the package's synthetic layer may not import) (seeded; the BLF's header
times are the frames' own; tests/test_docs.py checks the bytes).
"""

from __future__ import annotations

import io
import sys
import tempfile
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np

# The car of docs/vehicles.md, step 1 (the same options, in the same order).
MY_CAR_OPTIONS = ["--front-axle-mass-kg", "780", "--left-share", "0.51", "--track-m", "1.49",
                  "--kingpin-inclination-deg", "12.5", "--castor-deg", "4.2", "--scrub-radius-m", "0.01",
                  "--tyre-size", "185/65R15", "--tyre-pressure-bar", "2.3", "--steering-ratio", "15.3",
                  "--lock-turns", "2.6"]
MY_CAR_MAP = "RackPos[mm]=rack_m\nSteerTorque[N*m]=handwheel_torque_Nm\nSWA[deg]=handwheel_angle_rad\n"
CAR_CONDITIONS = [("unladen", "ground"), ("part_laden", "ground"), ("offset_12_7mm", "air_bearing")]
SEED = 3401


def _simulate(*argv: str) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """The columns and metadata of one `parksteer simulate` run (its CSV read back)."""
    from parksteer.cli import main

    with tempfile.TemporaryDirectory() as folder:
        out = Path(folder) / "run.csv"
        with redirect_stdout(io.StringIO()):
            if main(["simulate", *argv, "--output-dt", "0.01", "--quiet", "--out", str(out)]) != 0:
                raise RuntimeError(f"parksteer simulate {' '.join(argv)} failed")
        text = out.read_text(encoding="utf-8")
    lines = text.splitlines()
    metadata = dict(line[2:].split(": ", 1) for line in lines if line.startswith("# ") and ": " in line)
    rows = [line for line in lines if line and not line.startswith("#")]
    header = rows[0].split(",")
    data = np.array([[float(cell) for cell in row.split(",")] for row in rows[1:]])
    return {name: data[:, i] for i, name in enumerate(header)}, metadata


def write_car(folder: Path) -> list[Path]:
    """Three records of the pipeline's car data set (rack stiction hidden)."""
    import yaml

    from parksteer.parameters import DEFAULT_PATH
    from parksteer.synthetic.datasets import CarDesign, write_car_dataset

    root = Path(__file__).resolve().parents[2]
    config = yaml.safe_load((root / "config" / "config.yaml").read_text(encoding="utf-8"))
    car = dict(config["car"], files=[list(c) for c in CAR_CONDITIONS])
    design = CarDesign.from_config(car)
    folder.mkdir(parents=True, exist_ok=True)
    files = [folder / f"{case}__{surface}.csv" for case, surface in CAR_CONDITIONS]
    with tempfile.TemporaryDirectory() as scratch:
        write_car_dataset(str(DEFAULT_PATH), design, [str(f) for f in files], str(Path(scratch) / "truth.json"))
    return files


def write_my_car(folder: Path) -> list[Path]:
    """A logger's export of the docs' own car, and its channel map."""
    from parksteer.cli import main
    from parksteer.synthetic.logger import add_noise, quantise

    with tempfile.TemporaryDirectory() as scratch:
        vehicle = Path(scratch) / "my_car.toml"
        with redirect_stdout(io.StringIO()):
            if main(["vehicle", "new", "--out", str(vehicle), *MY_CAR_OPTIONS]) != 0:
                raise RuntimeError("parksteer vehicle new failed")
        columns, _ = _simulate("--vehicle", str(vehicle), "--case", "kerb", "--surface", "ground",
                               "--effects=+column_friction", "--set", "column_friction.friction_torque=0.5")
    rng = np.random.default_rng(SEED)
    time = columns["time_s"]
    rack_mm = quantise(add_noise(columns["rack_m"] * 1e3, 0.02, rng), 100.0, 14)
    torque = quantise(add_noise(columns["handwheel_torque_Nm"], 0.05, rng), 40.0, 12)
    angle_deg = quantise(add_noise(np.degrees(columns["handwheel_angle_rad"]), 0.05, rng), 1000.0, 16)
    lines = ["# source: synthetic logger export (data/samples/make_samples.py): the car of docs/vehicles.md, kerb "
             "load, on the ground, column friction 0.5 N m hidden",
             "# bits_rack_m: 14", "# bits_handwheel_torque_Nm: 12", "# bits_handwheel_angle_rad: 16",
             "Time[s],RackPos,SteerTorque,SWA"]
    lines += [f"{t:.2f},{r:.4f},{q:.4f},{a:.3f}" for t, r, q, a in zip(time, rack_mm, torque, angle_deg)]
    out = folder / "my_car" / "run1.csv"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("\n".join(lines) + "\n", encoding="utf-8")
    map_file = folder / "my_car.map"
    map_file.write_text("# the channels of data/samples/my_car/*.csv: logger name [unit] = column\n" + MY_CAR_MAP,
                        encoding="utf-8")
    return [out, map_file]


def write_polo_bus(folder: Path) -> list[Path]:
    """The assisted Polo's kerb cycle as its MQB powertrain CAN sends it, candump and BLF."""
    from parksteer.measure.bus import bus_channel_map, encode_frames, write_log
    from parksteer.measure.io import Measurement
    from parksteer.synthetic.logger import add_noise

    root = Path(__file__).resolve().parents[2]
    columns, _ = _simulate("--vehicle", str(root / "data" / "vehicles" / "polo_vi.toml"), "--with-assist",
                           "--case", "kerb", "--surface", "ground")
    rng = np.random.default_rng(SEED + 1)
    record = Measurement(None, {
        "time_s": columns["time_s"],
        "handwheel_torque_Nm": add_noise(columns["handwheel_torque_Nm"], 0.03, rng),
        "handwheel_angle_rad": add_noise(columns["handwheel_angle_rad"], 2e-4, rng),
    }, {"case": "kerb", "surface": "ground"})
    channels = bus_channel_map("vw_mqb", None, None, None)
    frames = encode_frames(record, channels)
    return [write_log(frames, folder / "polo_kerb.log", "candump"),
            write_log(frames, folder / "polo_kerb.blf", "blf")]


WORN_PEAK_N = 150.0
WORN_VARIATION = "rate_8pc_50Hz"


def _worn_centre():
    """The truth of ``worn_rack.csv``: an effect of this script, which the package and its diagnosis never see."""
    import sympy as sp

    from parksteer.model.symbolic.components import Effect
    from parksteer.model.symbolic.system import action_reaction
    from parksteer.parameters import Quantity

    class WornCentre(Effect):
        name = "sample_worn_centre"
        description = "Rack friction peaked at the centre, A / (1 + (x / 12 mm)^2) tanh(beta v)"
        in_default_set = False
        diagnosis_candidate = False
        quantities = (Quantity("sample_worn_centre.strength", "N", 0.0, 1e4, lower_inclusive=True, default=0.0,
                               source="data/samples/make_samples.py: the hidden truth of worn_rack.csv"),)
        uses = ("sample_worn_centre.strength", "steering.friction_smoothing")

        def loads(self, model):
            k = model.kinematics
            s = sp.tanh(model.p("steering.friction_smoothing") * model.rack_u)
            force = model.p("sample_worn_centre.strength") / (1 + (model.rack_q / 0.012) ** 2) * s
            return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)

    return WornCentre()


def write_worn_rack(folder: Path) -> list[Path]:
    """A record with a centre friction no candidate has, another hand and a 50 Hz logger's noise."""
    from parksteer.measure.io import write_measurement
    from parksteer.model.symbolic.components import resolve_effects
    from parksteer.parameters import load_parameters
    from parksteer.synthetic.datasets import BASE_PERTURBATION, perturbed_base
    from parksteer.synthetic.variations import VARIATIONS, variation_record

    params = load_parameters()
    variation = next(v for v in VARIATIONS if v.name == WORN_VARIATION)
    hand, logger = variation.settings(SEED + 2)
    base = perturbed_base(params, SEED + 2, BASE_PERTURBATION)
    truth = _worn_centre()
    record = variation_record(params, hand, logger, overrides={**base, "sample_worn_centre.strength": WORN_PEAK_N},
                              effects=[*resolve_effects(None), truth])
    out = folder / "worn_rack.csv"
    write_measurement(out, record, params)
    return [out]


# The Polo of the baseline-then-diagnose example (docs/assist_identify.md): its gear as built, not as the vehicle
# file's data say (torque constant and motor friction), and later with a motor that drags.
POLO_AS_BUILT = {"electric_assist_column.torque_constant": 0.055}
POLO_MOTOR_FRICTION = {"polo_baseline.csv": 0.03, "polo_drag.csv": 0.09, "polo_repaired.csv": 0.03}


def write_polo_records(folder: Path) -> list[Path]:
    """Three records of the assisted Polo as its bus logs them (torsion-bar torque in 0.01 N m, motor current in 0.1 A
    steps): a baseline, a later one with a motor that drags, and one after the motor's repair (its friction as at
    the baseline, another hand); a hand of the variation benchmark, the assisted replay of its rack
    (parksteer.synthetic.assisted, as the example record of docs/assist_diagnosis.md)."""
    from parksteer.measure.io import write_measurement
    from parksteer.model.symbolic.components import discover_effects
    from parksteer.synthetic.assisted import AssistedLogger, assisted_clean, assisted_record
    from parksteer.synthetic.variations import variation_by_name
    from parksteer.vehicle import load_vehicle

    root = Path(__file__).resolve().parents[2]
    discover_effects()  # the vehicle file's effect quantities (its [ackermann], [assist])
    params = load_vehicle(root / "data" / "vehicles" / "polo_vi.toml")
    variation = variation_by_name("rest_after_stop")
    out = []
    for k, (name, friction) in enumerate(POLO_MOTOR_FRICTION.items()):
        hand, _ = variation.settings(7 + k)
        overrides = {**POLO_AS_BUILT, "electric_assist_column.motor_friction_torque": friction}
        clean = assisted_clean(params, hand, "+electric_assist_column", "kerb", overrides=overrides)
        # the bus's steps, 2 full_scale / (2**bits - 1): 0.01 N m and 0.1 A
        logger = AssistedLogger(sample_rate_hz=100.0, rack_bits=variation.logger.rack_bits,
                                rack_noise_m=variation.logger.rack_noise_m, torque_bits=12, torque_full_scale_Nm=20.475,
                                torque_noise_Nm=0.003, current_bits=12, current_full_scale_A=204.75,
                                current_noise_A=0.02, seed=SEED + 10 + k)
        record = assisted_record(clean, logger, "kerb")
        record.metadata["source"] = (f"data/samples/make_samples.py: the assisted Polo, torque constant "
                                     f"{POLO_AS_BUILT['electric_assist_column.torque_constant']:g} N m/A, motor "
                                     f"friction {friction:g} N m, hand rest_after_stop seed {7 + k}")
        path = folder / name
        write_measurement(path, record, params)
        out.append(path)
    return out


def write_samples(folder: str | Path) -> list[Path]:
    folder = Path(folder)
    return [*write_car(folder / "car"), *write_my_car(folder), *write_polo_bus(folder), *write_worn_rack(folder),
            *write_polo_records(folder)]


if __name__ == "__main__":
    for path in write_samples(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent):
        print(path)
