"""Vehicle files: the car alone, read through the parameter registry, checked by statics and geometry at load."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from parksteer.cli import main
from parksteer.geometry import lock_steer_angle, steer_axis
from parksteer.parameters import DEFAULT_PATH, ParameterError, load_parameters
from parksteer.vehicle import REQUIRED, load_vehicle

ROOT = Path(__file__).resolve().parents[2]
VEHICLES = ROOT / "data" / "vehicles"
G = 9.81

SPEC = dict(mass_kg=780.0, left_share=0.51, track_m=1.49, kpi_deg=12.5, castor_deg=4.2, scrub_m=0.010,
            radius_m=0.31, pressure_bar=2.3, ratio=15.3, turns=2.6)


def _new(out: Path, *extra: str, **spec) -> int:
    s = {**SPEC, **spec}
    args = ["vehicle", "new", "--out", str(out), "--front-axle-mass-kg", str(s["mass_kg"]),
            "--left-share", str(s["left_share"]), "--track-m", str(s["track_m"]),
            "--kingpin-inclination-deg", str(s["kpi_deg"]), "--castor-deg", str(s["castor_deg"]),
            "--tyre-radius-m", str(s["radius_m"]), "--tyre-pressure-bar", str(s["pressure_bar"]),
            "--steering-ratio", str(s["ratio"]), "--lock-turns", str(s["turns"]), *extra]
    if "--kingpin-offset-m" not in extra:
        args += ["--scrub-radius-m", str(s["scrub_m"])]
    return main(args)


def test_paper_car_as_a_vehicle_file_is_the_shipped_car():
    """The paper's car written as a vehicle file (no rig, spacers or logger) loads to the same car values and cases
    as the full parameter file: a vehicle file needs only the car."""
    base = load_parameters(DEFAULT_PATH)
    car = load_vehicle(VEHICLES / "maestro.toml")
    text = (VEHICLES / "maestro.toml").read_text()
    assert not re.search(r"^\[(rig|spacers|synthetic)\]", text, re.M)
    for key in REQUIRED:
        assert car[key] == base[key], key
    assert car.cases == base.cases
    assert car["rig.loads"] == base["rig.loads"]  # what the car does not say comes from the base file


def test_every_shipped_vehicle_loads():
    """Each file under data/vehicles/ passes the registry, statics, geometry and lock checks."""
    files = sorted(VEHICLES.glob("*.toml"))
    assert len(files) >= 2
    for path in files:
        assert load_vehicle(path).case_names


def test_new_vehicle_statics_by_hand(tmp_path, capsys):
    """`vehicle new`: the wheel loads carry the front axle's weight split as given, the chassis mass closes the
    statics with the unsprung parts, its mass centre balances the load difference about the centreline (all by
    hand from the specification), and every derived value is printed with its derivation."""
    out = tmp_path / "hatch.toml"
    assert _new(out) == 0
    printed = capsys.readouterr().out
    car = load_vehicle(out)
    c = car.case("kerb")
    axle_N = SPEC["mass_kg"] * G
    assert c["load_left"] == pytest.approx(0.51 * axle_N, rel=1e-9)
    assert c["load_right"] == pytest.approx(0.49 * axle_N, rel=1e-9)
    unsprung = car["vehicle.unsprung_mass"]
    assert unsprung == pytest.approx(2 * car["steering.steering_assembly_mass"] + 2 * car["tyre.tread_ring_mass"]
                                     + car["steering.rack_mass"])
    assert c["chassis_mass"] == pytest.approx(SPEC["mass_kg"] - unsprung, rel=1e-9)
    # moments about the centreline: the chassis weight at y_cm against the wheel loads at the half track
    expected_cg = (0.49 - 0.51) * axle_N * (SPEC["track_m"] / 2) / ((SPEC["mass_kg"] - unsprung) * G)
    assert c["chassis_cg_y"] == pytest.approx(expected_cg, rel=1e-9)
    assert c["chassis_cg_y"] < 0.0  # heavier on the left: mass centre to the left (y right positive)
    for key in ("cases.kerb.chassis_mass", "cases.kerb.chassis_cg_y", "geometry.kingpin_top_y",
                "steering.handwheel_to_rack_ratio", "input.handwheel_lock_angle"):
        line = next(l for l in printed.splitlines() if l.strip().startswith(key))
        assert "derived" in line and " = " in line.split("]")[-1], line
    assert "assumed" in out.read_text()


@pytest.mark.parametrize("offset", ["scrub", "kingpin_offset"])
def test_new_vehicle_geometry_through_the_model_axis(tmp_path, offset):
    """The derived king-pin points give, through the model's own 3D steer axis (Rodrigues, geometry.steer_axis),
    the scrub radius and the inclinations asked for; the lock gives the road-wheel angle turns x pi / ratio."""
    out = tmp_path / "hatch.toml"
    chi, eps, r = math.radians(SPEC["kpi_deg"]), math.radians(SPEC["castor_deg"]), SPEC["radius_m"]
    if offset == "scrub":
        assert _new(out) == 0
        scrub = SPEC["scrub_m"]
    else:
        # king-pin offset at wheel-centre height: the scrub plus the axis' lateral run over the tyre radius
        offset_m = 0.08
        assert _new(out, "--kingpin-offset-m", str(offset_m)) == 0
        scrub = offset_m - r * math.tan(chi) / math.cos(eps)
    car = load_vehicle(out)
    for side in ("left", "right"):
        axis = steer_axis(car, "kerb", side)
        assert axis.scrub_radius_m() == pytest.approx(scrub, abs=1e-9)
        d = axis.direction
        assert math.atan2(abs(d[1]), math.hypot(d[0], d[2])) == pytest.approx(chi, abs=1e-12)  # KPI, front view
        assert math.atan2(d[0], d[2]) == pytest.approx(eps, abs=1e-12)  # castor, side view
        assert axis.wheel_radius_m == pytest.approx(r)
        # the axis passes through the wheel centre in side view (the paper's reconstruction): x = 0 at its height
        x_at_centre = axis.top[0] + (axis.wheel_centre[2] - axis.top[2]) * d[0] / d[2]
        assert x_at_centre == pytest.approx(0.0, abs=1e-12)
    assert lock_steer_angle(car) == pytest.approx(SPEC["turns"] * math.pi / SPEC["ratio"], rel=1e-9)


def test_tyre_size_radius(tmp_path):
    """185/65R15: rim 15 in / 2 + 185 mm x 0.65 = 0.1905 + 0.12025 m."""
    out = tmp_path / "sized.toml"
    args = ["vehicle", "new", "--out", str(out), "--front-axle-load-N", "7600", "--track-m", "1.5",
            "--kingpin-inclination-deg", "13", "--castor-deg", "4", "--scrub-radius-m", "0.01",
            "--tyre-size", "185/65R15", "--tyre-pressure-bar", "2.3", "--steering-ratio", "15", "--lock-turns", "2.7"]
    assert main(args) == 0
    car = load_vehicle(out)
    assert car["geometry.ground_z"] - car["geometry.wheel_centre_z"] == pytest.approx(0.31075)


def _refused(capsys, path: Path, key: str) -> str:
    assert main(["vehicle", "check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    assert str(path) in err and key in err, err
    return err


def _edit(src: Path, dst: Path, pattern: str, repl: str) -> Path:
    text, n = re.subn(pattern, repl, src.read_text(), count=1, flags=re.M)
    assert n == 1, pattern
    dst.write_text(text)
    return dst


@pytest.mark.parametrize("pattern, repl, key", [
    # a wheel load that does not add up with the masses
    (r"^(load_left = \{ value = )2698\.0", r"\g<1>2798.0", "cases.unladen.load_left"),
    # a negative wheel load
    (r"^(load_right = \{ value = )2878\.0", r"\g<1>-2878.0", "cases.unladen.load_right"),
    # a lock beyond the linear linkage (six turns each way at 22.3:1 is 97 degrees of road-wheel steer)
    (r"^(handwheel_lock_angle = \{ value = )12\.566", r"\g<1>37.7", "input.handwheel_lock_angle"),
    # the king-pin top outboard of the wheel centre
    (r"^(kingpin_top_y = \{ value = )0\.58", r"\g<1>0.9", "cases.unladen.wheel_centre_y"),
    # the wheel centre below the ground
    (r"^(wheel_centre_z = \{ value = )0\.2", r"\g<1>0.6", "geometry.wheel_centre_z"),
    # an unsprung mass the model's parts do not make
    (r"^(unsprung_mass = \{ value = )100\.0", r"\g<1>120.0", "vehicle.unsprung_mass"),
    # a key of the car left out
    (r"^castor_angle = .*\n", "", "geometry.castor_angle"),
    # a wrong unit
    (r'^(rack_mass = \{ value = 10\.0, unit = )"kg"', r'\g<1>"g"', "steering.rack_mass"),
])
def test_refusals_name_file_and_key(tmp_path, capsys, pattern, repl, key):
    """Statics, sign, geometry and lock defects are refused at load with one line naming the file and the key."""
    bad = _edit(VEHICLES / "maestro.toml", tmp_path / "bad.toml", pattern, repl)
    _refused(capsys, bad, key)


def test_new_refuses_an_impossible_car_and_writes_nothing(tmp_path, capsys):
    """A front axle lighter than the unsprung parts leaves a negative chassis mass: refused in one line naming the
    key, and no file is written."""
    out = tmp_path / "light.toml"
    assert _new(out, mass_kg=90.0) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "cases.kerb.chassis_mass" in err and str(out) in err
    assert not out.exists()


def test_vehicle_option_reaches_the_commands():
    """compare, diagnose and simulate take --vehicle; a bad vehicle file is one line with status 2 before any
    model runs."""
    for command in (["compare", "x.csv"], ["diagnose", "x.csv", "--json"], ["simulate", "--out", "x.csv"]):
        with pytest.raises(ParameterError, match="no_such.toml: cannot read"):
            from parksteer.cli import build_parser
            from parksteer.commands.vehicle import parameters_of

            args = build_parser().parse_args([*command, "--vehicle", "no_such.toml"])
            parameters_of(args)


def test_simulate_runs_the_vehicle_not_the_paper_car(tmp_path):
    """simulate --vehicle (no --case: the file's only load case) drives the handwheel to that car's lock, 2.85
    turns lock to lock = 2.85 pi rad each way, not the paper car's 4 pi, and starts from the file's wheel loads."""
    import numpy as np

    out = tmp_path / "polo.csv"
    assert main(["simulate", "--vehicle", str(VEHICLES / "polo_vi.toml"), "--out", str(out)]) == 0
    header = [l for l in out.read_text().splitlines() if l.startswith("#")]
    assert "# case: kerb" in header
    data = np.genfromtxt(out, delimiter=",", names=True, skip_header=len(header))
    assert np.max(np.abs(data["handwheel_angle_rad"])) == pytest.approx(2.85 * math.pi, rel=1e-3)
    car = load_vehicle(VEHICLES / "polo_vi.toml").case("kerb")
    assert data["load_left_N"][0] == pytest.approx(car["load_left"], abs=1.0)
    assert data["load_right_N"][0] == pytest.approx(car["load_right"], abs=1.0)


def _daq_csv(simulated: Path, out: Path) -> None:
    """A logger's export of a simulated record: semicolons, decimal commas, a units row, mm and degrees, CRLF, an
    extra channel."""
    import numpy as np

    header = [l for l in simulated.read_text().splitlines() if l.startswith("#")]
    d = np.genfromtxt(simulated, delimiter=",", names=True, skip_header=len(header))
    rows = ["Time;RackPos;SteerTorque;SWA;VehSpeed", "s;mm;N*m;deg;km/h"]
    for t, x, torque, angle in zip(d["time_s"], d["rack_m"], d["handwheel_torque_Nm"], d["handwheel_angle_rad"]):
        rows.append(";".join(f"{v:.6f}".replace(".", ",") for v in (t, 1000 * x, torque, math.degrees(angle), 0.0)))
    out.write_text("\r\n".join(rows) + "\r\n", encoding="utf-8")


def _plateau_rms(capsys, argv: list[str]) -> float:
    import json

    capsys.readouterr()
    assert main(argv) == 0
    result = json.loads(capsys.readouterr().out)
    return result["files"][0]["by_phase"]["plateau"]["rms"]


def test_compare_with_the_vehicle_replays_its_own_car(tmp_path, capsys):
    """A logger-style file of the Polo model's own cycle, compared with --vehicle (its case and surface given on
    the command line, the channels mapped with units), is reproduced on the sliding plateau to 0.01 N m: the
    replay of a model's own rack gives back its torque. The same file against the paper's car (its unladen case)
    is off by far more, so the vehicle's values, not the paper's, reached the replay."""
    simulated, daq = tmp_path / "polo_sim.csv", tmp_path / "polo_daq.csv"
    polo = str(VEHICLES / "polo_vi.toml")
    assert main(["simulate", "--vehicle", polo, "--out", str(simulated)]) == 0
    _daq_csv(simulated, daq)
    mapping = ["--map", "RackPos[mm]=rack_m,SteerTorque[N*m]=handwheel_torque_Nm,SWA[deg]=handwheel_angle_rad",
               "--surface", "ground", "--json"]
    own = _plateau_rms(capsys, ["compare", str(daq), "--vehicle", polo, "--case", "kerb", *mapping])
    paper = _plateau_rms(capsys, ["compare", str(daq), "--case", "unladen", *mapping])
    assert own < 0.01
    assert paper > 0.5
