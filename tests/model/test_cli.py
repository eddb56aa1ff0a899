"""The parksteer simulate / effects / derive commands."""

from __future__ import annotations

import json

import numpy as np

import pytest

from parksteer.cli import main
from parksteer.tables import read_csv


@pytest.mark.parametrize(
    "args",
    [
        ["--case", "no_such_case"],
        ["--case", "unladen", "--effects=-no_such_effect"],
        ["--case", "unladen", "--set", "steering.no_such=1"],
        ["--case", "unladen", "--set", "tyre_friction.tyre_pressure=200000"],
        ["--case", "unladen", "--set", "rack_lash.lash=0.0002"],
        ["--case", "unladen", "--set", "steering.rack_friction_force=-5"],
        ["--case", "unladen", "--set", "steering.rack_friction_force"],
        ["--case", "unladen", "--surface", "ice"],
        ["--case", "unladen", "--rack-from", "no_such_file.csv"],
    ],
)
def test_bad_arguments_exit_2_with_one_line_and_no_file(tmp_path, capsys, args):
    """A bad case, effect, parameter, value or drive file is a usage error: status 2, one line on stderr, no CSV."""
    out = tmp_path / "out.csv"
    with pytest.raises(SystemExit) if "--surface" in args else _no_exit():
        status = main(["simulate", *args, "--out", str(out)])
        assert status == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert not out.exists()


class _no_exit:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_unreadable_rack_file_is_a_usage_error(tmp_path, capsys):
    """A --rack-from file without time_s and rack_m columns is refused in one line, no output written."""
    bad = tmp_path / "bad.csv"
    bad.write_text("a,b\n1,2\n", encoding="utf-8")
    out = tmp_path / "out.csv"
    assert main(["simulate", "--case", "unladen", "--rack-from", str(bad), "--out", str(out)]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1
    assert not out.exists()


def test_simulate_writes_the_documented_columns_and_header(tmp_path):
    """The CSV has time, handwheel angle, rack, torque, loads and one contribution per effect plus inertia, and a
    header naming the case, surface, components and every parameter with its unit."""
    out = tmp_path / "sim.csv"
    assert main(["simulate", "--case", "part_laden", "--effects=-hooke_joint", "--surface", "air_bearing",
                 "--set", "steering.rack_friction_force=500", "--out", str(out)]) == 0
    columns, header = read_csv(out)
    for name in ("time_s", "handwheel_angle_rad", "rack_m", "handwheel_torque_Nm", "load_left_N", "load_right_N",
                 "contrib_tyre_friction_Nm", "contrib_rack_friction_Nm", "contrib_lifting_Nm",
                 "contrib_carcass_compliance_Nm", "contrib_inertia_Nm"):
        assert name in columns
    assert "contrib_hooke_joint_Nm" not in columns
    assert header["case"] == "part_laden" and header["surface"] == "air_bearing"
    assert header["param.steering.rack_friction_force"] == "500 N"
    assert header["param.tyre.radial_stiffness"] == "160000 N/m"
    assert abs(columns["time_s"][-1] - 18.0) < 1e-9


def test_effects_json_lists_parameters(capsys):
    """`parksteer effects --json` lists every effect with name, description, slot, needs and the quantities it
    uses by key (unit, default, bounds, source), the values of the parameter file."""
    assert main(["effects", "--json"]) == 0
    listed = {e["name"]: e for e in json.loads(capsys.readouterr().out)}
    assert {"tyre_friction", "rack_friction", "carcass_compliance", "lifting", "hooke_joint"} <= set(listed)
    friction = {p["key"]: p for p in listed["rack_friction"]["parameters"]}
    force = friction["steering.rack_friction_force"]
    assert force["default"] == 730.0 and force["unit"] == "N" and force["source"] == "Appendix B, F"
    assert listed["brush_patch"]["requires"] == ["carcass_compliance", "tyre_friction"]
    assert listed["hooke_joint"]["replaces"] == "column_map"


def test_renamed_key_is_refused_naming_the_key(tmp_path, capsys):
    """A key of an earlier version (tyre_friction.tyre_pressure, once a second name of the file's tyre pressure)
    is refused in one line that names the one key of the quantity, tyre.tyre_pressure; nothing is written."""
    out = tmp_path / "out.csv"
    assert main(["simulate", "--case", "unladen", "--set", "tyre_friction.tyre_pressure=200000",
                 "--out", str(out)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1
    assert "tyre_friction.tyre_pressure" in lines[0] and "this quantity is tyre.tyre_pressure" in lines[0]
    assert not out.exists()


def test_speed_option_runs_the_rolling_tyre(tmp_path, capsys):
    """simulate --speed-kmh adds the rolling tyre at that speed: at 3 km/h the peak handwheel torque is well below
    the standstill's (the wheel rolls about 2 m per radian of steer on the paper's cycle); out of 0-10.8 km/h it
    is refused in one line."""

    peaks = {}
    for speed in ("0", "3"):
        out = tmp_path / f"run_{speed}.csv"
        assert main(["simulate", "--case", "unladen", "--speed-kmh", speed, "--out", str(out)]) == 0
        columns, header = read_csv(out)
        assert "turn_slip" in header["components"]
        peaks[speed] = float(np.max(np.abs(columns["handwheel_torque_Nm"])))
    assert peaks["3"] < 0.5 * peaks["0"]
    assert main(["simulate", "--case", "unladen", "--speed-kmh", "20", "--out", str(tmp_path / "x.csv")]) == 2
    assert "--speed-kmh 20: outside 0-10.8 km/h" in capsys.readouterr().err
