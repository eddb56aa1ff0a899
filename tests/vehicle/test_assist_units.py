"""The units guard of a boost table: a table whose largest point, carried to the rack, no car's assist asks for is
refused in one line naming the unit its numbers most likely are in and the key or flag that fixes it."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import pytest

from parksteer.cli import main
from parksteer.model.numeric.assist import check_assist, rack_force_window_N, table_rack_force_N
from parksteer.vehicle import load_vehicle

DATA = Path(__file__).resolve().parents[2] / "data/vehicles"
POLO, GOLF_IV = DATA / "polo_vi.toml", DATA / "golf_iv.toml"
NAME = "electric_assist_column"
ASSIST_LINE = re.compile(r"^assist = \{ value = \[([^\]]*)\], unit = \"N m\"", re.MULTILINE)


def polo_with_table(tmp_path: Path, scale: float, at: str | None = None) -> Path:
    """The Polo's file with its [assist.boost] assist divided by `scale` (and `at` = ... added to the entry)."""
    text = POLO.read_text(encoding="utf-8")
    values = [float(v) for v in ASSIST_LINE.search(text)[1].split(",")]
    scaled = ", ".join(repr(v / scale) for v in values)
    extra = f', at = "{at}"' if at else ""
    text = ASSIST_LINE.sub(f'assist = {{ value = [{scaled}], unit = "N m"{extra}', text)
    out = tmp_path / "polo_motor.toml"
    out.write_text(text, encoding="utf-8")
    return out


def eta_n(params) -> float:
    return params[f"{NAME}.efficiency"] * params[f"{NAME}.reduction_ratio"]


def test_a_motor_torque_curve_written_as_column_torque_is_refused_by_check_and_simulate(tmp_path, capsys):
    """The Polo's boost curve written in motor torque (its column assist over eta N = 0.85 x 18 = 15.3) and read as
    a column torque asks the rack for 3.8 kN / 15.3 = 250 N at its largest point, a twelfth of the car's 3.0 kN
    standstill load: `vehicle check` and `simulate` refuse it (exit status 2) with one line naming the file, the
    key, the motor torque as the likely unit and both fixes (the file's at = "motor", the command's
    --assist-boost-unit motor), and simulate writes nothing."""
    polo = load_vehicle(POLO)
    good, _ = table_rack_force_N(polo, NAME)
    low, high = rack_force_window_N()
    assert low <= good <= high  # the Polo's own table is a car's
    bad = polo_with_table(tmp_path, eta_n(polo))
    for argv in (["vehicle", "check", str(bad)],
                 ["simulate", "--vehicle", str(bad), "--with-assist", "--case", "kerb", "--out",
                  str(tmp_path / "run.csv"), "--quiet"]):
        capsys.readouterr()
        assert main(argv) == 2
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1
        assert str(bad) in err and "assist.boost.assist" in err and "motor" in err
        assert 'at = \\"motor\\"' in err or 'at = "motor"' in err
        assert "--assist-boost-unit motor" in err
        assert f"{good / eta_n(polo):.0f} N" in err  # the force it asks for, a 15.3th of the table's own
    assert not (tmp_path / "run.csv").exists()


def test_the_same_curve_marked_as_motor_torque_is_the_cars_table(tmp_path, capsys):
    """Marked at = "motor", the same numbers are carried to the column through eta N: the table's scalars are the
    Polo's own (within rounding), and `vehicle check` says the file is valid."""
    polo = load_vehicle(POLO)
    fixed = polo_with_table(tmp_path, eta_n(polo), at="motor")
    params = load_vehicle(fixed)
    assert check_assist(params) == NAME
    for k in range(9):
        key = f"{NAME}.boost_assist_0_{k}"
        assert params[key] == pytest.approx(polo[key], rel=1e-12, abs=1e-12)
    assert main(["vehicle", "check", str(fixed)]) == 0
    # a point of action the assist does not have is no unit
    text = fixed.read_text(encoding="utf-8").replace('at = "motor"', 'at = "rack"')
    fixed.write_text(text, encoding="utf-8")
    capsys.readouterr()
    assert main(["vehicle", "check", str(fixed)]) == 2
    assert "assist.boost.assist.at: 'rack'" in capsys.readouterr().err


def test_a_rack_force_written_as_column_torque_is_refused_naming_the_rack_force(tmp_path, capsys):
    """The other slip: a curve of rack forces (N) written as column torques asks for G_hr = 125.5 times the force:
    refused, naming a rack force as the likely unit."""
    polo = load_vehicle(POLO)
    bad = polo_with_table(tmp_path, 1.0 / polo["steering.handwheel_to_rack_ratio"])
    capsys.readouterr()
    assert main(["vehicle", "check", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "a rack force (N) written as a torque at the column" in err


def test_new_refuses_motor_points_given_as_column_torque_and_writes_nothing(tmp_path, capsys):
    """`vehicle new --assist column --assist-boost ...` without --assist-boost-unit takes the points at the column;
    a motor curve (1.2 N m at its top) given so asks for 1.2 x 118 = 140 N at the rack: refused naming
    --assist-boost-unit motor, no file written; with the flag the same points are the car's table."""
    spec = ["--front-axle-mass-kg", "860", "--track-m", "1.549", "--kingpin-inclination-deg", "14", "--castor-deg",
            "7", "--scrub-radius-m", "0.01", "--tyre-size", "205/55R16", "--tyre-pressure-bar", "2.3",
            "--steering-ratio", "14.1", "--lock-turns", "2.1", "--assist", "column", "--assist-boost",
            "0.5:0,1.5:0.2,3:1.2"]
    out = tmp_path / "car.toml"
    capsys.readouterr()
    assert main(["vehicle", "new", "--out", str(out), *spec]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--assist-boost-unit motor" in err
    assert not out.exists()
    assert main(["vehicle", "new", "--out", str(out), *spec, "--assist-boost-unit", "motor"]) == 0


def test_a_valve_table_in_bar_written_as_pa_is_refused_naming_bar(tmp_path, capsys):
    """The Golf IV's valve table (up to 69 bar on a 8 cm^2 piston: 5.5 kN) written with unit "Pa" asks for 1e-5 of
    it: refused naming bar."""
    boost = tomllib.loads(GOLF_IV.read_text(encoding="utf-8"))["assist"]["boost"]
    assert boost["assist"]["unit"] == "bar"
    text = GOLF_IV.read_text(encoding="utf-8")
    marker = 'assist = { value = ['
    start = text.index(marker, text.index("[assist.boost]"))
    end = text.index("\n", start)
    bad_line = text[start:end].replace('unit = "bar"', 'unit = "Pa"')
    bad = tmp_path / "golf_pa.toml"
    bad.write_text(text[:start] + bad_line + text[end:], encoding="utf-8")
    capsys.readouterr()
    assert main(["vehicle", "check", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "bar written as Pa" in err
