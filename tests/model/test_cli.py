"""The parksteer simulate / effects / derive commands."""

from __future__ import annotations

import json

import pytest

from parksteer.cli import main
from parksteer.tables import read_csv


@pytest.mark.parametrize(
    "args",
    [
        ["--case", "no_such_case"],
        ["--case", "unladen", "--effects=-no_such_effect"],
        ["--case", "unladen", "--set", "rack_friction.no_such=1"],
        ["--case", "unladen", "--set", "rack_friction.friction_force=-5"],
        ["--case", "unladen", "--set", "rack_friction.friction_force"],
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
                 "--set", "rack_friction.friction_force=500", "--out", str(out)]) == 0
    columns, header = read_csv(out)
    for name in ("time_s", "handwheel_angle_rad", "rack_m", "handwheel_torque_Nm", "load_left_N", "load_right_N",
                 "contrib_tyre_friction_Nm", "contrib_rack_friction_Nm", "contrib_lifting_Nm",
                 "contrib_carcass_compliance_Nm", "contrib_inertia_Nm"):
        assert name in columns
    assert "contrib_hooke_joint_Nm" not in columns
    assert header["case"] == "part_laden" and header["surface"] == "air_bearing"
    assert header["param.rack_friction.friction_force"] == "500 N"
    assert header["param.tyre.radial_stiffness"] == "160000 N/m"
    assert abs(columns["time_s"][-1] - 18.0) < 1e-9


def test_effects_json_lists_parameters(capsys):
    """`parksteer effects --json` lists every effect with name, description and parameters (unit, default, bounds)."""
    assert main(["effects", "--json"]) == 0
    listed = {e["name"]: e for e in json.loads(capsys.readouterr().out)}
    assert {"tyre_friction", "rack_friction", "carcass_compliance", "lifting", "hooke_joint"} <= set(listed)
    friction = {p["name"]: p for p in listed["rack_friction"]["parameters"]}
    assert friction["friction_force"]["default"] == 730.0 and friction["friction_force"]["unit"] == "N"
